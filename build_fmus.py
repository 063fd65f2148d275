#!/usr/bin/env python3
"""Build fmus/*.fmu and ssp/*.ssp from their sources (same as ``cranefmu build``)."""
import sys

from cranefmu.cli import main

if __name__ == "__main__":
    sys.exit(main(["build", *sys.argv[1:]]))
