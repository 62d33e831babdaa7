"""The ``battgen`` command line: argparse and printing only, one module per command.

:mod:`.main` holds the parser and the list / ir / generate commands; every other command is a
module here exposing ``register(subparsers)``, which adds its parser with ``set_defaults(func=...)``.
A command function takes the parsed arguments, drives an engine of :mod:`codegen.apps` and prints
what it hands back; it returns the exit code.
"""
