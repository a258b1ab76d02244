"""Image bytes for model requests (ignjax.sim.views.encode): round trips
decoded with Pillow, order, thread-count independence, agreement between
the installed encoders, data URLs and the errors on bad input."""

from __future__ import annotations

import base64
import io
import sys

import numpy as np
import pytest
from PIL import Image

from ignjax.errors import ConfigError
from ignjax.sim.views import encode
from ignjax.sim.views.encode import (ENCODERS, PACKAGES, PREFERRED, available_encoders, data_url, default_encoder,
                                     encode_images)

JPEG = available_encoders("jpeg")
PNG = available_encoders("png")


def decode(b: bytes) -> np.ndarray:
    with Image.open(io.BytesIO(b)) as im:
        return np.asarray(im.convert("RGB"))


def scenes(n: int = 5, h: int = 96, w: int = 128) -> np.ndarray:
    """Smooth test images (gradients and a block), different for each index."""
    y, x = np.mgrid[0:h, 0:w]
    out = np.empty((n, h, w, 3), np.uint8)
    for i in range(n):
        out[i, ..., 0] = (x * 255 // (w - 1) + 40 * i) % 256
        out[i, ..., 1] = (y * 255 // (h - 1)) // (i + 1)
        out[i, ..., 2] = (30 + 40 * i) % 256
        out[i, 20 + 5 * i:50 + 5 * i, 30:70] = ((250 - 30 * i) % 256, (20 * i) % 256, 200)
    return out


def test_pillow_is_always_there_and_defaults_are_installed():
    assert "pillow" in JPEG and "pillow" in PNG
    for fmt in ("jpeg", "png"):
        d = default_encoder(fmt)
        assert d == next(n for n in PREFERRED[fmt] if n in available_encoders(fmt))


@pytest.mark.parametrize("encoder", PNG)
def test_png_round_trip_is_lossless_and_ordered(encoder):
    imgs = scenes()
    out = encode_images(imgs, "png", encoder=encoder)
    assert len(out) == len(imgs) and all(b.startswith(b"\x89PNG") for b in out)
    for i, b in enumerate(out):
        assert np.array_equal(decode(b), imgs[i])


@pytest.mark.parametrize("encoder", JPEG)
def test_jpeg_round_trip_is_close_and_ordered(encoder):
    imgs = scenes()
    out = encode_images(imgs, "jpg", 90, encoder=encoder)
    assert all(b.startswith(b"\xff\xd8") for b in out)
    decoded = np.stack([decode(b) for b in out]).astype(int)
    assert decoded.shape == imgs.shape
    err = np.abs(decoded[:, None] - imgs[None].astype(int)).mean(axis=(2, 3, 4))  # (decoded i, image j)
    assert np.all(np.diag(err) < 3.0)
    assert np.array_equal(err.argmin(axis=1), np.arange(len(imgs)))  # each decodes nearest its own image


@pytest.mark.parametrize("fmt", ["jpeg", "png"])
def test_threads_do_not_change_the_bytes(fmt):
    imgs = scenes(9)
    serial = encode_images(imgs, fmt, threads=1)
    assert encode_images(imgs, fmt, threads=3) == serial
    assert encode_images(imgs, fmt) == serial
    assert encode_images(imgs[:0], fmt) == []


def test_quality_trades_size_for_error():
    img = scenes(1)
    small, large = encode_images(img, "jpeg", 20)[0], encode_images(img, "jpeg", 95)[0]
    assert len(small) < len(large)
    assert np.abs(decode(small).astype(int) - img[0]).mean() > np.abs(decode(large).astype(int) - img[0]).mean()


@pytest.mark.parametrize("fmt", ["jpeg", "png"])
def test_installed_encoders_agree(fmt):
    imgs = scenes(3)
    ref = [decode(b).astype(int) for b in encode_images(imgs, fmt, 90, encoder="pillow")]
    ref_size = sum(len(b) for b in encode_images(imgs, fmt, 90, encoder="pillow"))
    for name in available_encoders(fmt):
        out = encode_images(imgs, fmt, 90, encoder=name)
        assert 0.8 < sum(len(b) for b in out) / ref_size < 1.25, name
        for r, b in zip(ref, out):
            d = decode(b)
            assert d.shape == r.shape
            assert np.abs(d - r).mean() < (0.01 if fmt == "png" else 1.5), name


def test_missing_encoder_names_the_package(monkeypatch):
    # an encoder that cannot be imported (here: its import blocked through sys.modules)
    monkeypatch.setattr(encode, "_MODULES", {})
    monkeypatch.setitem(sys.modules, "simplejpeg", None)
    monkeypatch.setitem(sys.modules, "cv2", None)
    for name in ("simplejpeg", "opencv"):
        with pytest.raises(ConfigError, match=f"views.encode.encoder.*pip install {PACKAGES[name]}"):
            encode_images(scenes(1), "jpeg", encoder=name)
    assert default_encoder("jpeg") == "pillow"  # the default falls back to Pillow
    assert decode(encode_images(scenes(1), "jpeg")[0]).shape == (96, 128, 3)


def test_data_url():
    b = encode_images(scenes(1), "png")[0]
    url = data_url(b, "png")
    assert url.startswith("data:image/png;base64,")
    assert base64.b64decode(url.split(",", 1)[1]) == b
    assert data_url(b"\xff\xd8", "jpg").startswith("data:image/jpeg;base64,")
    with pytest.raises(ConfigError, match="views.encode.format"):
        data_url(b, "gif")


@pytest.mark.parametrize("kwargs, where", [
    (dict(images=scenes(1).astype(np.float32)), "views.encode.images"),
    (dict(images=scenes(1)[0]), "views.encode.images"),
    (dict(images=scenes(1)[..., :2]), "views.encode.images"),
    (dict(fmt="gif"), "views.encode.format"),
    (dict(fmt=None), "views.encode.format"),
    (dict(quality=0), "views.encode.quality"),
    (dict(quality=101), "views.encode.quality"),
    (dict(quality=90.5), "views.encode.quality"),
    (dict(quality=True), "views.encode.quality"),
    (dict(encoder="libjpeg"), "views.encode.encoder"),
    (dict(fmt="png", encoder="simplejpeg"), "views.encode.encoder"),
    (dict(threads=0), "views.encode.threads"),
])
def test_bad_input_names_the_field(kwargs, where):
    kwargs = {"images": scenes(1), **kwargs}
    with pytest.raises(ConfigError, match=where.replace(".", r"\.")):
        encode_images(**kwargs)


def test_encoders_table_is_consistent():
    assert set(ENCODERS) == set(PACKAGES)
    for fmt, names in PREFERRED.items():
        assert names[-1] == "pillow" and all(fmt in ENCODERS[n] for n in names)
