"""The trainer's learning curve: ``curve.csv`` (one row per update) and ``curve.png``."""

from __future__ import annotations

import csv
from pathlib import Path

from ignjax.fileio import atomic_write

COLUMNS = ("update", "steps", "wall_s", "episodes", "return", "success", "questions", "length", "reward",
           "loss_policy", "loss_value", "entropy", "approx_kl", "lr")
"""The columns of ``curve.csv``."""


def read_curve(path: Path, upto: int) -> list[dict]:
    """The curve's rows of updates 1 .. ``upto`` (a resumed run drops what came after its checkpoint)."""
    if not path.is_file():
        return []
    with path.open() as fh:
        return [row for row in csv.DictReader(fh) if int(row["update"]) <= upto]


def write_curve(out: Path, rows: list[dict]) -> None:
    """``curve.csv`` and ``curve.png`` (return and success of the ended episodes against environment steps)."""
    import io

    buf = io.StringIO()
    w = csv.DictWriter(buf, COLUMNS, lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    atomic_write(out / "curve.csv", buf.getvalue())
    if rows:
        plot_curve(out / "curve.png", rows)


def plot_curve(path: Path, rows: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    steps = [float(r["steps"]) / 1e6 for r in rows]
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.2))
    for ax, key, label in zip(axes, ("return", "success", "questions"),
                              ("return (WSR@1.5)", "success rate", "questions / episode")):
        ax.plot(steps, [float(r[key]) for r in rows], lw=1)
        ax.set_xlabel("environment steps (M)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    tmp = path.with_name(path.name + ".tmp.png")
    fig.savefig(tmp, dpi=100, metadata={"Software": None})
    plt.close(fig)
    tmp.replace(path)


__all__ = ["COLUMNS", "plot_curve", "read_curve", "write_curve"]
