"""Command-line entry point.

The CLI is thin: each sub-command module parses its arguments, calls the library, and writes
results. Every module in ``_COMMAND_MODULES`` exposes ``register(subparsers)``, which adds its
sub-parser(s) and sets ``func`` (a callable taking the parsed namespace and returning an exit
code). Heavy imports happen inside the handlers so that ``seisrack --help`` stays fast.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Sequence

from seisrack import __version__

_COMMAND_MODULES = (
    "seisrack.cli.modal",
    "seisrack.cli.sdof",
    "seisrack.cli.validate",
    "seisrack.cli.motion",
    "seisrack.cli.run",
    "seisrack.cli.paper",
    "seisrack.cli.study",
    "seisrack.cli.export",
    "seisrack.cli.report",
    "seisrack.cli.design",
)


#: set by :func:`main` when the command line asks for ``--json``: errors are JSON too
_JSON_ERRORS = False


class _Parser(argparse.ArgumentParser):
    """argparse parser whose usage errors exit with code 2 and a one-line message (a JSON
    error object on stdout under ``--json``)."""

    def error(self, message: str) -> None:  # pragma: no cover - exercised via CLI tests
        if _JSON_ERRORS:
            from seisrack.cli._common import error_object, print_json_error

            print_json_error(error_object(message=f"{self.prog}: {message}",
                                          allowed="see --help"))
            self.exit(2)
        self.print_usage(sys.stderr)
        self.exit(2, f"seisrack: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="seisrack",
        description="Earthquake response of steel pallet racks with sliding pallets.",
    )
    parser.add_argument("--version", action="version", version=f"seisrack {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in _COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:  # a command group not yet present in this build
            if exc.name == name:
                continue
            raise
        module.register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; every failure becomes the one-paragraph error (see
    :mod:`seisrack.cli._boundary`), and a closed output pipe ends the command quietly."""
    global _JSON_ERRORS
    from seisrack.cli._boundary import quiet_broken_pipe

    _JSON_ERRORS = "--json" in (sys.argv[1:] if argv is None else list(argv))
    verbose = False
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        verbose = bool(getattr(args, "verbose", False))
        logging.basicConfig(
            level=logging.INFO if verbose else logging.WARNING,
            format="%(levelname)s %(name)s: %(message)s",
        )
        func = getattr(args, "func", None)
        if func is None:
            parser.print_help(sys.stderr)
            return 2
        code = int(func(args) or 0)
        sys.stdout.flush()  # a closed pipe shows here, inside the boundary
        return code
    except BrokenPipeError:
        quiet_broken_pipe()
        return 0
    except SystemExit:
        raise  # argparse: --help, --version and usage errors (already reported)
    except BaseException as exc:  # noqa: BLE001 - the one boundary: nothing escapes as a traceback
        return _fail(exc, verbose)


def _fail(exc: BaseException, verbose: bool) -> int:
    """Report ``exc`` as one paragraph on stderr, or as the JSON object on stdout."""
    from seisrack.cli._boundary import describe, quiet_broken_pipe, want_traceback

    f = describe(exc)
    if f.internal and want_traceback(verbose):
        import traceback

        traceback.print_exception(exc, file=sys.stderr)
    try:
        if _JSON_ERRORS:
            from seisrack.cli._common import error_object, print_json_error

            print_json_error(error_object(message=f.message, field=f.field, value=f.value,
                                          allowed=f.allowed))
            sys.stdout.flush()
        else:
            print(f"seisrack: error: {f.message}", file=sys.stderr)
    except BrokenPipeError:
        quiet_broken_pipe()
    return f.code
