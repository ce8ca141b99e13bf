"""``python -m cablelife`` and the ``cablelife`` script: the command line.

Ctrl-C ends every command with exit code 130 and no traceback, also while the modules are
still being imported (which takes a moment: numpy, scipy, h5py, pydantic, rich, typer)."""

import sys

EXIT_INTERRUPTED = 130


def main() -> None:
    try:
        from cablelife.cli import app
        from cablelife.interrupt import report_exit
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        sys.exit(EXIT_INTERRUPTED)
    try:
        app(prog_name="cablelife")
    except SystemExit as exit_:
        report_exit(exit_.code)
        raise
    except KeyboardInterrupt:  # outside the command (typer turns it into exit code 130 inside)
        report_exit(EXIT_INTERRUPTED)
        sys.exit(EXIT_INTERRUPTED)


if __name__ == "__main__":
    main()
