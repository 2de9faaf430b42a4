"""The one exception type users see. The CLI turns it into ``Error: ...`` and an exit code."""

from __future__ import annotations


class WallcliError(Exception):
    """A failure the user can act on: bad input, failed work. Exit code 1 by default."""

    exit_code = 1

    def __init__(self, message: str, hint: str | None = None, exit_code: int | None = None):
        super().__init__(message)
        self.message = message
        self.hint = hint
        if exit_code is not None:
            self.exit_code = exit_code

    def __str__(self) -> str:
        return self.message if not self.hint else f"{self.message} ({self.hint})"


class UsageError(WallcliError):
    """A malformed option value or a combination of options that makes no sense (exit 2)."""

    exit_code = 2
