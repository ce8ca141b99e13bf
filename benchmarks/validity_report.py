"""Runs a benchmark's main() and prints the distinct validity warnings its runs gave (strain
limits, unresolved impacts, ...): a speed figure is only worth something for a scene inside the
model's range, so the reader sees whether it was."""

from __future__ import annotations

import warnings
from collections.abc import Callable


def run_reporting_warnings(main: Callable[[], None]) -> None:
    """main(), then "validity warnings: none" or each distinct warning once."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        main()
    seen = sorted({f"{w.category.__name__}: {w.message}" for w in caught})
    print("validity warnings:", "none" if not seen else "")
    for text in seen:
        print("  " + text)
