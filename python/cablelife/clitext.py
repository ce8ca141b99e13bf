"""Printing for the command line: every dynamic text (names, paths, messages, keys) is escaped
so that Rich never reads ``[/x]`` or ``:x:`` in it as markup or emoji, and warnings are shown
as one ``warning:`` line each."""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from contextlib import contextmanager

from rich.console import Console
from rich.markup import escape

__all__ = ["console", "escape", "print_error", "print_warning", "printed_warnings"]


def console(stderr: bool = False) -> Console:
    """A console that prints text as given: no emoji codes, no automatic highlighting."""
    return Console(stderr=stderr, emoji=False, highlight=False)


def print_error(out: Console, message) -> None:
    """``error: message`` (the message escaped)."""
    out.print(f"[bold red]error:[/] {escape(str(message))}", highlight=False, soft_wrap=True)


def print_warning(out: Console, message) -> None:
    out.print(f"[yellow]warning:[/] {escape(str(message))}", highlight=False, soft_wrap=True)


@contextmanager
def printed_warnings(out: Console) -> Iterator[list]:
    """Collects the warnings of the block and prints each once as a ``warning:`` line."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            yield caught
        finally:
            seen = set()
            for w in caught:
                text = str(w.message)
                if text not in seen:
                    seen.add(text)
                    print_warning(out, text)
