"""Crane subsystem physics: parameters, right-hand sides and outputs, pure numpy.

Nothing in this package knows about FMI.  Every import inside it is relative, because the build
bundles it into each FMU under a build-unique package name (see ``cranefmu.build``).
"""
