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
)


class _Parser(argparse.ArgumentParser):
    """argparse parser whose usage errors exit with code 2 and a one-line message."""

    def error(self, message: str) -> None:  # pragma: no cover - exercised via CLI tests
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
        print(f"seisrack: error: {exc}", file=sys.stderr)
        return 2
    except FileNotFoundError as exc:
        print(f"seisrack: error: file not found: {exc.filename}", file=sys.stderr)
        return 2
    except IsADirectoryError as exc:
        print(f"seisrack: error: expected a file, got a directory: {exc.filename}", file=sys.stderr)
        return 2
    except PermissionError as exc:
        print(f"seisrack: error: permission denied: {exc.filename}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("seisrack: interrupted", file=sys.stderr)
        return 130
