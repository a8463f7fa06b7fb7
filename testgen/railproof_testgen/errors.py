"""Errors reported to the user as one line naming file, entry and reason."""


class SpecError(Exception):
    """A malformed, duplicate or dangling entry in spec/ (or in a model/vector file), a file
    that cannot be read within the loader's limits, or an output that cannot be written."""

    def __init__(self, file, entry, reason):
        self.file, self.entry, self.reason = str(file), str(entry), str(reason)
        super().__init__(f"{self.file}: {self.entry}: {self.reason}")


class OutputError(SpecError, OSError):
    """An output that cannot be written (``file: -: cannot write: reason``): reported like
    every SpecError, and an OSError for a caller that handles the file system's errors."""


class PipelineError(Exception):
    """A pipeline step failed (property violated, tool missing, empty result...)."""
