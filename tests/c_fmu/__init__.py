"""C FMUs compiled for tests only (flags.c, integrator.c); the shared compiler lookup is cranefmu_support.c_fmu.build."""
