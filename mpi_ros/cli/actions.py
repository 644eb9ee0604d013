"""``mpi-ros stop``, ``e-stop``, ``abort``, ``reset``, ``resume``: one mpiMotionAction each.

Each verb's module is a docstring (its help) plus ``add_arguments, run = verb("STOP")``.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable

from .console import add_target_options, print_reply, run_verb


def verb(action: str) -> tuple[Callable[[argparse.ArgumentParser], None], Callable[[argparse.Namespace], int]]:
    """The (add_arguments, run) pair of the verb that sends ``action``."""

    def add_arguments(parser: argparse.ArgumentParser) -> None:
        add_target_options(parser)

    def run(args: argparse.Namespace) -> int:
        def body(session) -> int:
            call = session.action_call(args.supervisor)
            return print_reply(action, call.call(action, args.timeout, raise_on_error=False), args.supervisor)

        return run_verb(args, body)

    return add_arguments, run
