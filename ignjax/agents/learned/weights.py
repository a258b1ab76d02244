"""A trained policy's weights as plain arrays, and its forward pass in ``jax.numpy``.

The trainer's network (:class:`ignjax.rl.policy.Policy`, flax) is, per step:
``layers`` dense layers with tanh (the encoder), a GRU cell or nothing (the
core), then two linear heads, the logits over the actions and the value.
:func:`forward` computes the same with ``jax.numpy`` alone (flax's
``Dense``: ``x @ kernel + bias``; flax's ``GRUCell``: ``r = sigmoid(ir(x) +
hr(h))``, ``z = sigmoid(iz(x) + hz(h))``, ``n = tanh(in(x) + r * hn(h))``,
``h' = (1 - z) n + z h``, with biases on the input side and on ``hn``), so
that evaluating a policy needs no flax (the ``[rl]`` extra); a test checks
it against ``Policy.apply``.

**Weights file** (:data:`WEIGHTS_FILE`, ``policy.npz``): one array per name,
float32:

=============================  ======================  =========================
name                           shape                   what
=============================  ======================  =========================
``encoder_<i>/kernel``, ``/bias``  (D or H, H), (H,)   encoder layer i (0-based)
``core/<g>/kernel``            (H, H)                  GRU, g in ir, iz, in, hr, hz, hn
``core/<g>/bias``              (H,)                    g in ir, iz, in, hn
``logits/kernel``, ``/bias``   (H, A), (A,)            the action logits
``value/kernel``, ``/bias``    (H, 1), (1,)            the value head
=============================  ======================  =========================

(D: the observation vector's length, H: ``hidden``, A: the actions.) No
``core/*`` array means the ``mlp`` core. The network's shape
(:class:`NetShape`) is read from these shapes, never from a flax module.
:func:`write_npz` writes the arrays in name order with fixed zip
timestamps, so the same weights give the same bytes (and the same SHA-256,
which the run records name).
"""

from __future__ import annotations

import io
import re
import zipfile
from dataclasses import dataclass
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.errors import InputError

WEIGHTS_FILE = "policy.npz"
"""The weights file's name in a checkpoint or exported policy folder."""
MASKED_LOGIT = -1e9
"""The logit a masked action gets."""
GRU_GATES = ("ir", "iz", "in", "hr", "hz", "hn")
"""The GRU's dense maps (flax ``GRUCell``'s names): input (``i*``) and recurrent (``h*``) parts of the reset,
update and candidate gates."""
GRU_BIASED = ("ir", "iz", "in", "hn")
"""The GRU maps with a bias."""
CORES = ("gru", "mlp")
"""The cores: a GRU over the episode (memory) or none."""


@dataclass(frozen=True)
class NetShape:
    """The network's shape, read from its weights (hashable: a program's static description).

    Attributes:
        core: "gru" or "mlp".
        hidden: width of the encoder's layers and of the core.
        layers: dense layers of the encoder.
        obs_dim: length of the observation vector it reads.
        n_actions: actions it scores.
    """

    core: str
    hidden: int
    layers: int
    obs_dim: int
    n_actions: int

    def settings(self) -> dict:
        """The network's settings as the trainer's checkpoint record holds them (``policy``)."""
        return {"core": self.core, "hidden": self.hidden, "layers": self.layers}

    def names(self) -> list[str]:
        """Every array name a weights file of this shape holds, in file order."""
        out = [f"encoder_{i}/{p}" for i in range(self.layers) for p in ("kernel", "bias")]
        if self.core == "gru":
            out += [f"core/{g}/kernel" for g in GRU_GATES] + [f"core/{g}/bias" for g in GRU_BIASED]
        return sorted(out + ["logits/kernel", "logits/bias", "value/kernel", "value/bias"])

    def shapes(self) -> dict[str, tuple[int, ...]]:
        """``name -> shape`` of every array."""
        D, H, A = self.obs_dim, self.hidden, self.n_actions
        out = {}
        for i in range(self.layers):
            out[f"encoder_{i}/kernel"], out[f"encoder_{i}/bias"] = (D if i == 0 else H, H), (H,)
        if self.core == "gru":
            out.update({f"core/{g}/kernel": (H, H) for g in GRU_GATES})
            out.update({f"core/{g}/bias": (H,) for g in GRU_BIASED})
        out.update({"logits/kernel": (H, A), "logits/bias": (A,), "value/kernel": (H, 1), "value/bias": (1,)})
        return out


def shape_of(weights, where="weights") -> NetShape:
    """The :class:`NetShape` of a weights mapping (numpy or JAX arrays; works under a trace: shapes only).

    Raises:
        InputError: naming ``where`` and the array that is missing, unexpected or of the wrong shape.
    """
    names = set(weights)
    layers = len({m.group(1) for n in names if (m := re.fullmatch(r"encoder_(\d+)/kernel", n))})
    for need in ("encoder_0/kernel", "logits/kernel"):
        if need not in names:
            raise InputError(str(where), need, "missing: not a policy's weights file")
    D, H = (int(s) for s in np.shape(weights["encoder_0/kernel"]))
    A = int(np.shape(weights["logits/kernel"])[-1])
    shape = NetShape("gru" if any(n.startswith("core/") for n in names) else "mlp", H, layers, D, A)
    want = shape.shapes()
    for name in sorted(names | set(want)):
        if name not in want:
            raise InputError(str(where), name, f"unexpected array for a {shape.core} network of {layers} layers")
        if name not in names:
            raise InputError(str(where), name, f"missing from a {shape.core} network of {layers} layers")
        if tuple(np.shape(weights[name])) != want[name]:
            raise InputError(str(where), name, f"shape {tuple(np.shape(weights[name]))}, expected {want[name]} "
                                               f"(hidden {H}, {D} observation entries, {A} actions)")
    return shape


def _dense(weights, name: str, x):
    y = x @ weights[f"{name}/kernel"]
    bias = weights.get(f"{name}/bias")
    return y if bias is None else y + bias


def forward(weights, carry, obs, first, mask):
    """One step of the network (flax ``Policy.__call__``'s equations; any leading batch axes).

    Args:
        weights: ``name -> array`` (module docstring).
        carry: (..., H) the core's state before the step.
        obs: (..., D) observation vectors.
        first: (...) bool, the step begins an episode (the GRU's state is zeroed first).
        mask: (..., A) bool, the allowed actions.

    Returns:
        (carry (..., H), logits (..., A) with disallowed entries at :data:`MASKED_LOGIT`, value (...)).
    """
    shape = shape_of(weights)
    x = obs
    for i in range(shape.layers):
        x = jnp.tanh(_dense(weights, f"encoder_{i}", x))
    if shape.core == "gru":
        h = jnp.where(jnp.asarray(first)[..., None], 0.0, carry)
        g = lambda name, v: _dense(weights, f"core/{name}", v)  # noqa: E731
        r = jax.nn.sigmoid(g("ir", x) + g("hr", h))
        z = jax.nn.sigmoid(g("iz", x) + g("hz", h))
        n = jnp.tanh(g("in", x) + r * g("hn", h))
        carry = (1.0 - z) * n + z * h
        x = carry
    logits = _dense(weights, "logits", x)
    value = _dense(weights, "value", x)[..., 0]
    return carry, jnp.where(mask, logits, MASKED_LOGIT), value


# ---------------------------------------------------------------------------
# the trainer's (flax) parameter tree <-> the flat names
# ---------------------------------------------------------------------------


def from_flax(params) -> dict[str, np.ndarray]:
    """The flat weights (``name -> float32 array``) of the trainer's parameter tree
    (``{"params": {"Dense_0": ..., "GRUCell_0": ...}}``, as ``Policy.init`` returns and ``policy.msgpack`` holds).

    The ``Dense_<k>`` modules are, in creation order, the encoder's layers, the logits head and the value head.
    """
    tree = params.get("params", params)
    dense = sorted((k for k in tree if k.startswith("Dense_")), key=lambda k: int(k.split("_")[1]))
    if len(dense) < 3:
        raise InputError("policy", "params", f"expected the encoder's and both heads' Dense layers, got {sorted(tree)}")
    out = {}
    names = [f"encoder_{i}" for i in range(len(dense) - 2)] + ["logits", "value"]
    for name, key in zip(names, dense):
        for p, v in tree[key].items():
            out[f"{name}/{p}"] = v
    for g, parts in tree.get("GRUCell_0", {}).items():
        for p, v in parts.items():
            out[f"core/{g}/{p}"] = v
    return {k: np.asarray(v, np.float32) for k, v in sorted(out.items())}


def to_flax(weights) -> dict:
    """The trainer's parameter tree of flat weights (the inverse of :func:`from_flax`)."""
    shape = shape_of(weights)
    tree: dict = {}
    heads = [f"encoder_{i}" for i in range(shape.layers)] + ["logits", "value"]
    for k, name in enumerate(heads):
        tree[f"Dense_{k}"] = {p: jnp.asarray(weights[f"{name}/{p}"]) for p in ("kernel", "bias")}
    if shape.core == "gru":
        tree["GRUCell_0"] = {g: {p: jnp.asarray(weights[f"core/{g}/{p}"]) for p in ("kernel", "bias")
                                 if f"core/{g}/{p}" in weights} for g in GRU_GATES}
    return {"params": tree}


# ---------------------------------------------------------------------------
# the file
# ---------------------------------------------------------------------------


def npz_bytes(weights) -> bytes:
    """The ``.npz`` file of ``weights`` (``numpy.load`` reads it): arrays in name order, fixed timestamps, so the
    same weights give the same bytes."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        for name in sorted(weights):
            info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            with zf.open(info, "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, np.ascontiguousarray(np.asarray(weights[name], np.float32)),
                                          allow_pickle=False)
    return buf.getvalue()


def read_npz(path: Path) -> dict[str, np.ndarray]:
    """The weights in ``path`` (``name -> float32 array``).

    Raises:
        InputError: naming the file: missing, not an ``.npz`` of arrays, or an array that is not float32.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(str(path), None, "no such file")
    try:
        with np.load(path, allow_pickle=False) as data:
            out = {name: data[name] for name in data.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as e:
        raise InputError(str(path), None, f"not a weights file (.npz of arrays): {e}") from None
    for name, a in out.items():
        if a.dtype != np.float32:
            raise InputError(str(path), name, f"dtype {a.dtype}, expected float32")
    return out


__all__ = ["CORES", "GRU_BIASED", "GRU_GATES", "MASKED_LOGIT", "NetShape", "WEIGHTS_FILE", "forward", "from_flax",
           "npz_bytes", "read_npz", "shape_of", "to_flax"]
