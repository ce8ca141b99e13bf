"""Errors and warnings of the signal generator."""

from __future__ import annotations


class SignalError(ValueError):
    """Bad signal input (file, channel, time grid, value) with a message that says what to fix."""


class SignalWarning(UserWarning):
    """A signal was generated, but differs from what was asked (e.g. content above Nyquist)."""
