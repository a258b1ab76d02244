"""``python -m ignjax.rl.export``: a trained policy as a plain weights file, for the ``learned`` agent.

::

    python -m ignjax.rl.export RUN_OR_CHECKPOINT                 # write policy.npz into the checkpoint
    python -m ignjax.rl.export RUN_OR_CHECKPOINT --out DIR       # and an exported policy folder DIR

``RUN_OR_CHECKPOINT`` is a checkpoint folder ``<run>/checkpoints/<update>``
or a training run folder (its newest checkpoint). The trainer writes
``policy.npz`` beside ``policy.msgpack`` at every checkpoint; a checkpoint
of a run made before it did gets its ``policy.npz`` here
(:func:`convert`, from ``policy.msgpack``: needs the ``rl`` extra's flax).
With ``--out``, ``DIR/policy.npz`` and ``DIR/record.json`` (the checkpoint's
record, the weights' SHA-256, where it was exported from and the training
run's configuration) form an exported policy folder
(:func:`export`), which ``--set agents.learned.checkpoint=DIR`` plays; the
shipped policy is one (``ignjax/data/policy``; its ``README.md`` gives the
command that made it). The export is checked as the agent checks it, before
it is written.

Exit status 0; 2 on an error (not a checkpoint, a record that does not
fit this package), with one line on stderr.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path

from ignjax.agents.learned.record import EXPORTED_RECORD, read_record
from ignjax.agents.learned.source import Loaded, load, locate
from ignjax.agents.learned.weights import WEIGHTS_FILE, from_flax, npz_bytes
from ignjax.errors import IgnjaxError, InputError
from ignjax.errors.extras import optional_module, require_extra
from ignjax.fileio import atomic_write
from ignjax.sim.types import SimConfig

serialization = optional_module("flax.serialization", "rl")

MSGPACK = "policy.msgpack"
"""The flax-serialised weights the trainer writes in every checkpoint."""


def convert(checkpoint: Path) -> Path:
    """Write ``policy.npz`` of the checkpoint folder from its ``policy.msgpack`` (flax); returns its path.

    Raises:
        InputError: no ``policy.msgpack`` there, or one that is not the trainer's network.
        MissingExtra: flax is not installed.
    """
    checkpoint = Path(checkpoint)
    src = checkpoint / MSGPACK
    if not src.is_file():
        raise InputError(str(src), None, "missing: the checkpoint holds no weights to convert")
    require_extra("flax", "rl")
    try:
        tree = serialization.msgpack_restore(src.read_bytes())
    except Exception as e:  # msgpack's own errors: a damaged or foreign file
        raise InputError(str(src), None, f"not flax-serialised weights: {e}") from None
    return atomic_write(checkpoint / WEIGHTS_FILE, npz_bytes(from_flax(tree)))


def _training(checkpoint: Path) -> tuple[dict, SimConfig]:
    """The training run's ``run.json`` (its fingerprint and configuration; {} when absent) and its simulator
    configuration."""
    meta = checkpoint.parent.parent / "run.json"
    if not meta.is_file():
        return {}, SimConfig()
    run = json.loads(meta.read_text())
    sim = SimConfig.from_values(run.get("config", {}).get("sim", {}), str(meta))
    return {"fingerprint": run.get("fingerprint"), "config": run.get("config")}, sim


def export(source: str | Path, out: Path | None = None) -> Loaded:
    """The checkpoint ``source`` names with its ``policy.npz`` (converted when absent), and with ``out`` the
    exported policy folder ``out`` (module docstring); returns what was written, loaded and checked (``out``, or
    the checkpoint).

    Raises:
        InputError: not a checkpoint, or one the ``learned`` agent would refuse under the training's simulator
            configuration.
    """
    checkpoint = locate(str(source), "checkpoint")
    if (checkpoint / EXPORTED_RECORD).is_file():
        raise InputError(str(checkpoint), "checkpoint", "already an exported policy; give the training run's "
                                                        "checkpoint")
    if not (checkpoint / WEIGHTS_FILE).is_file():
        convert(checkpoint)
    training, sim = _training(checkpoint)
    loaded = load(checkpoint, sim)  # refused here as the agent would refuse it
    if out is None:
        return loaded
    data = (checkpoint / WEIGHTS_FILE).read_bytes()
    rec = {**read_record(checkpoint), "weights_sha256": hashlib.sha256(data).hexdigest(),
           "exported_from": f"{checkpoint.parent.parent.name}/{checkpoint.parent.name}/{checkpoint.name}",
           "training": training}
    out = Path(out)
    atomic_write(out / WEIGHTS_FILE, data)
    atomic_write(out / EXPORTED_RECORD, json.dumps(rec, indent=2, sort_keys=True) + "\n")
    return load(out, sim)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m ignjax.rl.export", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("checkpoint", help="a checkpoint folder RUN/checkpoints/<update>, or a training run folder (its "
                                      "newest checkpoint)")
    p.add_argument("--out", help="write an exported policy folder here (policy.npz and record.json)")
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(sys.argv[1:] if argv is None else list(argv))
    try:
        loaded = export(args.checkpoint, Path(args.out) if args.out else None)
    except IgnjaxError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    folder = loaded.folder
    print(f"wrote {folder / WEIGHTS_FILE} (sha256 {loaded.sha256}, {loaded.shape.core} network, hidden "
          f"{loaded.shape.hidden}, {loaded.shape.layers} layers, update {loaded.record.get('update')})"
          + (f" and {folder / EXPORTED_RECORD}" if args.out else ""))
    return 0


__all__ = ["MSGPACK", "convert", "export", "main"]

if __name__ == "__main__":
    sys.exit(main())
