"""Exports in worker processes that survive a worker's death.

A worker can die without an exception: a log mapped from a file system that fails under it, the
kernel's out-of-memory killer, a crash in a native library. ``ProcessPoolExecutor`` then fails
every task it still holds with ``BrokenProcessPool``, the finished and the never-started alike,
and names none of them. Here each task tells when it starts; after a break the tasks that never
started run again in a new pool, and those that had started (the one that died among them) each
run alone in a process of its own, where a death is that log's and is reported as its failure
with the signal that ended it. The other logs of the run are exported either way.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
import signal
from collections.abc import Callable, Iterator
from concurrent.futures.process import BrokenProcessPool
from multiprocessing.connection import Connection
from typing import Any, Protocol


class Failed(Protocol):
    """Makes the result of a log whose worker died."""

    def __call__(self, path: str, why: str) -> Any: ...


_started: Any = None  # in a worker: the queue that tasks report their start on


def _init(started: Any) -> None:
    global _started
    _started = started


def _tracked(task: Callable[[str], Any], path: str) -> Any:
    _started.put(path)
    return task(path)


def run_pooled(task: Callable[[str], Any], paths: list[str], jobs: int, failed: Failed) -> Iterator[Any]:
    """``task(path)`` for every path in ``jobs`` processes, results in the order they finish; a path
    whose process dies gets ``failed(path, why)``. ``task`` must be picklable (a module-level function
    or a ``functools.partial`` of one)."""
    context = multiprocessing.get_context()
    pending = list(paths)
    while pending:
        started = context.SimpleQueue()
        done: set[str] = set()
        broken = False
        with concurrent.futures.ProcessPoolExecutor(jobs, context, initializer=_init, initargs=(started,)) as pool:
            futures = {pool.submit(_tracked, task, p): p for p in pending}
            for fut in concurrent.futures.as_completed(futures):
                try:
                    result = fut.result()
                except BrokenProcessPool:
                    broken = True
                    continue
                done.add(futures[fut])
                yield result
        if not broken:
            return
        began: set[str] = set()
        while not started.empty():
            began.add(started.get())
        if not began - done:  # the pool broke before any task ran: nothing to tell them apart, each alone
            began = set(pending)
        for path in [p for p in pending if p in began and p not in done]:
            yield run_alone(task, path, failed)
            done.add(path)
        pending = [p for p in pending if p not in done]


def _child(task: Callable[[str], Any], path: str, out: Connection) -> None:
    try:
        out.send((True, task(path)))
    except Exception as exc:  # raised as the pool would raise it: in the caller
        out.send((False, exc))
    out.close()


def run_alone(task: Callable[[str], Any], path: str, failed: Failed) -> Any:
    """``task(path)`` in a process of its own: its result, or ``failed`` saying how the process ended."""
    context = multiprocessing.get_context()
    receive, send = context.Pipe(duplex=False)
    process = context.Process(target=_child, args=(task, path, send), daemon=True)
    process.start()
    send.close()
    try:
        ok, result = receive.recv()
    except EOFError:  # the process ended without a result
        ok, result = True, None
    process.join()
    receive.close()
    if not ok:
        raise result
    if result is not None:
        return result
    return failed(path, f"the export process died ({_ending(process.exitcode)}); the other logs went on")


def _ending(code: int | None) -> str:
    if code is not None and code < 0:
        try:
            return f"killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit code {code}"
