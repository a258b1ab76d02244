"""Which episodes of an MLLM agent are done, which run again, and what a
run that met model failures tells its user.

**The progress file** ``<out>/llm/<agent>.progress.jsonl``
(:class:`ProgressLog`): a header line ``{"settings", "agent", "episodes"}``,
then one line per episode as it ends (outcome, trajectory, accounting,
``failure``, transcript records), appended, flushed and synced. A run
started again with the same settings reads it (a file written with other
settings is refused):

* an episode that ended normally (STOP or the step budget) is done: it is
  not run again and its line is what the outputs show;
* an episode that ended by a model failure (``failure`` non-empty; stop
  reason ``model_failure``) is run again from its start. Its requests that
  were answered before the failure come from the reply cache (nothing is
  charged twice: the simulator replays the same decisions), so only what
  failed is sent again. Its new line follows the old one, and the last line
  of an episode is the one that counts.

**Exit status.** A command whose MLLM agents had any episode end by a model
failure still writes every output (atomically), then prints one line per
such agent on stderr (:func:`report_model_failures`: how many episodes of
which agent, the first reason, and that running the command again retries
them) and exits with :data:`MODEL_FAILURE_EXIT`.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

from ignjax.errors import InputError
from ignjax.fileio import atomic_write

MODEL_FAILURE_EXIT = 3
"""Exit status of ``python -m ignjax.evaluate`` and ``python -m ignjax.sweep`` when an MLLM agent's episode ended
by a model failure (outputs written; 0: none did; 2: an error stopped the command before its outputs)."""


class ProgressLog:
    """One agent's progress file (module docstring); ``path`` None: no file (nothing kept, nothing written)."""

    def __init__(self, path: Path | None, key: str, agent: str, episodes: int):
        self.path, self.key, self.agent, self.episodes = path, key, agent, episodes
        self._fh = None

    def load(self) -> tuple[dict[int, dict], set[int]]:
        """``(done, failed)``: the records of the episodes that ended normally, by index, and the indices of
        the episodes whose last record ended by a model failure (to run again).

        Raises:
            InputError: the file's header is unreadable or names other settings.
        """
        if self.path is None or not self.path.exists():
            return {}, set()
        lines = self.path.read_text(encoding="utf-8").split("\n")
        try:
            head = json.loads(lines[0])
        except (json.JSONDecodeError, IndexError):
            raise InputError(self.path, "line 1", "not a progress header; delete the file to start over") from None
        if head.get("settings") != self.key:
            raise InputError(self.path, "settings", "the run there was made with other settings (episodes, agent, "
                                                    "model, simulator, views, seed or costs); use another --out or "
                                                    "delete it")
        last: dict[int, dict] = {}
        for line in lines[1:]:
            try:
                rec = json.loads(line)
            except json.JSONDecodeError:
                continue  # the last line of a killed run may be cut
            last[int(rec["index"])] = rec
        failed = {i for i, rec in last.items() if rec.get("failure")}
        return {i: rec for i, rec in last.items() if i not in failed}, failed

    def open(self) -> "ProgressLog":
        """Write the header if the file is new, and open it for appending."""
        if self.path is not None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            if not self.path.exists():
                atomic_write(self.path, json.dumps({"settings": self.key, "agent": self.agent,
                                                    "episodes": self.episodes}) + "\n")
            self._fh = open(self.path, "a", encoding="utf-8")
        return self

    def append(self, entry: dict) -> None:
        """One ended episode's record, flushed and synced."""
        if self._fh is not None:
            self._fh.write(json.dumps(entry) + "\n")
            self._fh.flush()
            os.fsync(self._fh.fileno())

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None


def report_model_failures(failures: dict[str, list[str]], again: str, file=None) -> int:
    """Print, on stderr, one line per agent of ``failures`` (agent -> the ``failure`` text of each of its
    episodes, "" where none) with episodes ended by a model failure; ``again`` says how to retry them
    (e.g. "run the same command again"). Returns :data:`MODEL_FAILURE_EXIT` if any did, else 0."""
    file = sys.stderr if file is None else file
    status = 0
    for agent, texts in failures.items():
        failed = [t for t in texts if t]
        if not failed:
            continue
        status = MODEL_FAILURE_EXIT
        print(f"{agent}: {len(failed)} of {len(texts)} episodes ended by a model failure (first: {failed[0]}); "
              f"{again} to run them again (their answered requests come from the reply cache)", file=file)
    return status


__all__ = ["MODEL_FAILURE_EXIT", "ProgressLog", "report_model_failures"]
