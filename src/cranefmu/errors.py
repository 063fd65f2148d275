"""Exceptions of cranefmu (a leaf module every layer may import): each names the item, its value and what is allowed."""


class CraneFmuError(Exception):
    """Base of every error a user can cause or meet; the CLI prints it without a traceback."""


class SceneError(CraneFmuError):
    """The scene or .ssp is missing, malformed, or its connections do not fit the FMUs."""


class ParameterSetError(CraneFmuError):
    """A parameter set or ``--set`` override names an unknown variable or has a wrong value."""


class SettingsError(CraneFmuError):
    """A run setting (stop time, step, algorithm, ...) is out of range."""


class SimulationError(CraneFmuError):
    """The run failed part-way: a component failed or a value became non-finite.

    ``result`` holds the rows computed before the failure, ``output`` the CSV they were written to.
    """

    def __init__(self, message: str, result=None, output=None):
        super().__init__(message)
        self.result = result
        self.output = output

    def __reduce__(self):  # keep the partial result when the error crosses a process boundary
        return (type(self), (str(self), self.result, self.output))


class CompositionError(SceneError):
    """A scene source (ssp/<scene>/scene.toml) names an unknown component, port or variable, or connects
    two ends whose units or directions do not fit; the message names the file, the line and the port."""
