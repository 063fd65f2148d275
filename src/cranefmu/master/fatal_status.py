"""A mixin for fmpy's slave classes (FMI 2.0 and 3.0) that remembers a status fatal."""
from __future__ import annotations


class FatalAware:
    """Mixin for fmpy's slave classes: remember a status fatal (:attr:`fatal`), after which FMI allows
    no further call on the instance."""

    fatal = False

    def _call(self, fname, *args):
        from fmpy.fmi1 import FMICallException

        try:
            return super()._call(fname, *args)
        except FMICallException as err:
            if err.status == 4:
                self.fatal = True
            raise
