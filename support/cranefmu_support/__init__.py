"""Test and benchmark scaffolding, not shipped in the wheel: FMUs run in a fresh child process
(``fmu_child``), hand-written SSPs (``foreign_ssp``), every physics model's test configurations
(``model_cases``), the master's two-mass test problem (``oscillator``, ``late``), a C host of our FMUs
(``c_host``) and a C FMU (``c_fmu``).  tests/conftest.py puts ``support/`` on sys.path; a benchmark
does so with ``sys.path.insert(0, <repository>/support)``.
"""
