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
from seisrack.errors import SeisrackError

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
    global _JSON_ERRORS
    _JSON_ERRORS = "--json" in (sys.argv[1:] if argv is None else list(argv))
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if getattr(args, "verbose", False) else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    func = getattr(args, "func", None)
    if func is None:
        parser.print_help(sys.stderr)
        return 2
    try:
        return int(func(args) or 0)
    except SeisrackError as exc:
        return _error(exc, str(exc))
    except FileNotFoundError as exc:
        return _error(exc, f"file not found: {exc.filename}", "file", exc.filename,
                      "an existing file")
    except IsADirectoryError as exc:
        return _error(exc, f"expected a file, got a directory: {exc.filename}", "file",
                      exc.filename, "a file")
    except PermissionError as exc:
        return _error(exc, f"permission denied: {exc.filename}", "file", exc.filename,
                      "a readable/writable path")
    except KeyboardInterrupt:
        print("seisrack: interrupted", file=sys.stderr)
        return 130


def _error(exc: BaseException, message: str, field: str | None = None, value: object = None,
           allowed: str | None = None) -> int:
    """Report a user error: one paragraph on stderr, or a JSON object on stdout with --json."""
    if _JSON_ERRORS:
        from seisrack.cli._common import error_object, print_json_error

        obj = (error_object(exc) if hasattr(exc, "field") else
               error_object(message=message, field=field, value=value, allowed=allowed))
        print_json_error(obj)
    else:
        print(f"seisrack: error: {message}", file=sys.stderr)
    return 2
