"""Co-simulation master for FMI 2.0 co-simulation FMUs described by an SSP.  Knows nothing of cranes."""
