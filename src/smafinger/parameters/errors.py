"""The error every bad parameter or option value raises."""


class ParameterError(ValueError):
    """A parameter or option value is missing, of the wrong type, or outside its allowed range."""
