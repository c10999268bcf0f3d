"""The exceptions of the Python module (docs/python.md)."""


class InputError(ValueError):
    """A bad input, as ``cairn run`` reports it (exit code 2).

    Attributes: ``file`` (the input file, ``"--set <text>"`` for an override, the ``name`` given
    to ``from_dict``), ``line`` (1-based, 0 when unknown), ``key`` (dotted key, "" when the error
    concerns no single key), ``expected`` and ``found``; ``errors`` lists every independent
    mistake of the input (this one first), each an InputError. ``str(error)`` is the CLI's message.
    """

    def __init__(self, message, file="", line=0, key="", expected="", found=""):
        super().__init__(message)
        self.file = file
        self.line = line
        self.key = key
        self.expected = expected
        self.found = found
        self.errors = (self,)
