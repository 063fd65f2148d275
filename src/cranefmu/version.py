"""The version of cranefmu (a leaf: the package, the cache and the native FMUs' descriptions read it)."""

__version__ = "0.1.0"
