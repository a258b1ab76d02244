"""Image bytes for model requests: a batch of uint8 images to PNG or JPEG.

:func:`encode_images` encodes ``(R, H, W, 3)`` uint8 RGB images, in order,
on a thread pool (the C encoders release the GIL while they work; one pool
per thread count, created on first use and reused). :func:`data_url` wraps the bytes
for an OpenAI-style ``image_url`` content part.

Encoders (``encoder=``): ``"pillow"`` (always there: a core dependency),
``"simplejpeg"`` (JPEG only; ``pip install simplejpeg``) and ``"opencv"``
(``pip install opencv-python-headless``). All of them write baseline JPEG
with 4:2:0 chroma subsampling at the given quality (libjpeg-turbo in each:
Pillow and OpenCV decode to identical pixels, simplejpeg's differ from them
by 0.3 grey levels on average) and PNG at zlib level
:data:`PNG_COMPRESS_LEVEL` (fastest; ``quality`` does not apply to PNG).
``encoder=None`` takes the first installed of :data:`PREFERRED`: simplejpeg
for JPEG, Pillow for PNG.

Measured on this project's 2-core development machine (Python 3.11, Pillow
13.0.0 with libjpeg-turbo 3, simplejpeg 1.9.0, opencv-python-headless
5.1.0), encoding 32 Planner panels (3 x 3 sheets of the rendered views in
``docs/house_0_004_panorama.png`` resized to S, via ``planner_panels``),
JPEG at quality 90. Images per second, best of 5 repeats, median and range
over 3 runs x ``threads`` 1 and 2 (other jobs held the load average at 2-3,
so a second thread gained nothing measurable and the spread is about 20%)::

    panel                 JPEG pillow    simplejpeg   opencv    | PNG pillow  opencv
    672 x 672   (S=224)   570 (520-620)  700 (650-820) 700 (650-780) | 66 (56-77) 70 (58-86)
    1344 x 1344 (S=448)   150 (140-190)  215 (190-270) 190 (175-240) | 19 (16-23) 17 (16-18)

Sizes: JPEG 94 kB (672 px) and 279 kB (1344 px), mean absolute error 1.7
and 1.2 grey levels; PNG (level 1) 177 kB and 442 kB. simplejpeg is the
fastest JPEG encoder (about 1.25x Pillow at 672 px and 1.4x at 1344 px,
slightly ahead of OpenCV, for a far smaller package); for PNG Pillow and
OpenCV are within noise, so Pillow stays the PNG default. The command
(from the repository root)::

    python - <<'EOF'
    import time, numpy as np
    from PIL import Image
    from ignjax.sim.views.compose import panel_layout, planner_panels
    from ignjax.sim.views.encode import encode_images
    pano = np.asarray(Image.open("docs/house_0_004_panorama.png").convert("RGB"))
    cells = [pano[r*256:(r+1)*256, c*256:(c+1)*256] for r, c in panel_layout(8)[2]]
    for S in (224, 448):
        v = np.stack([np.asarray(Image.fromarray(x).resize((S, S), Image.BILINEAR)) for x in cells])
        imgs = planner_panels(np.stack([np.roll(v, k, 0) for k in range(32)]))
        for fmt, encs in (("jpeg", ("pillow", "simplejpeg", "opencv")), ("png", ("pillow", "opencv"))):
            for enc in encs:
                for threads in (1, 2):
                    times = []
                    for _ in range(5):
                        t = time.perf_counter()
                        out = encode_images(imgs, fmt, 90, encoder=enc, threads=threads)
                        times.append(time.perf_counter() - t)
                    print(imgs.shape[1], fmt, enc, threads, round(len(imgs) / min(times)), len(out[0]) // 1000)
    EOF
"""

from __future__ import annotations

import base64
import io
import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from PIL import Image

from ignjax.errors import ConfigError

FORMATS = ("jpeg", "png")
PNG_COMPRESS_LEVEL = 1
"""zlib level of PNG output: level 1 measured 1.5-2x as fast as Pillow's
default 6 on the panels below, for files 20-25% larger."""
ENCODERS: dict[str, tuple[str, ...]] = {"pillow": ("jpeg", "png"), "simplejpeg": ("jpeg",), "opencv": ("jpeg", "png")}
"""The formats each encoder writes."""
PREFERRED: dict[str, tuple[str, ...]] = {"jpeg": ("simplejpeg", "pillow"), "png": ("pillow",)}
"""Default encoder per format: the first one installed (measured fastest first)."""
PACKAGES = {"pillow": "pillow", "simplejpeg": "simplejpeg", "opencv": "opencv-python-headless"}
"""The pip package of each encoder."""
_MIME = {"jpeg": "image/jpeg", "png": "image/png"}

_POOLS: dict[int, ThreadPoolExecutor] = {}
_LOCK = threading.Lock()
_MODULES: dict[str, object] = {}


def _module(name: str):
    """The encoder's module, or None when it is not installed."""
    if name not in _MODULES:
        try:
            if name == "simplejpeg":
                import simplejpeg as mod
            elif name == "opencv":
                import cv2 as mod
            else:
                import PIL.Image as mod
        except ImportError:
            mod = None
        _MODULES[name] = mod
    return _MODULES[name]


def available_encoders(fmt: str) -> tuple[str, ...]:
    """Installed encoders that write ``fmt`` ("jpeg" or "png")."""
    fmt = _check_format(fmt)
    return tuple(n for n, fmts in ENCODERS.items() if fmt in fmts and _module(n) is not None)


def default_encoder(fmt: str) -> str:
    """The encoder ``encoder=None`` uses for ``fmt``: the first installed of :data:`PREFERRED`."""
    fmt = _check_format(fmt)
    return next(n for n in PREFERRED[fmt] if _module(n) is not None)


def _pillow(img: np.ndarray, fmt: str, quality: int) -> bytes:
    buf = io.BytesIO()
    if fmt == "jpeg":
        Image.fromarray(img).save(buf, "JPEG", quality=quality, subsampling=2)
    else:
        Image.fromarray(img).save(buf, "PNG", compress_level=PNG_COMPRESS_LEVEL)
    return buf.getvalue()


def _simplejpeg(img: np.ndarray, fmt: str, quality: int) -> bytes:
    return _module("simplejpeg").encode_jpeg(img, quality=quality, colorspace="RGB", colorsubsampling="420")


def _opencv(img: np.ndarray, fmt: str, quality: int) -> bytes:
    cv2 = _module("opencv")
    bgr = cv2.cvtColor(img, cv2.COLOR_RGB2BGR)
    if fmt == "jpeg":
        params = [cv2.IMWRITE_JPEG_QUALITY, quality, cv2.IMWRITE_JPEG_SAMPLING_FACTOR,
                  cv2.IMWRITE_JPEG_SAMPLING_FACTOR_420]
        ok, buf = cv2.imencode(".jpg", bgr, params)
    else:
        ok, buf = cv2.imencode(".png", bgr, [cv2.IMWRITE_PNG_COMPRESSION, PNG_COMPRESS_LEVEL])
    if not ok:
        raise RuntimeError(f"OpenCV could not encode a {img.shape} image as {fmt}")
    return buf.tobytes()


_ENCODE = {"pillow": _pillow, "simplejpeg": _simplejpeg, "opencv": _opencv}


def _check_format(fmt) -> str:
    f = fmt.lower() if isinstance(fmt, str) else fmt
    f = "jpeg" if f == "jpg" else f
    if f not in FORMATS:
        raise ConfigError(None, "views.encode.format", f"{fmt!r}: must be 'png' or 'jpeg'")
    return f


def _check_encoder(encoder, fmt: str) -> str:
    if encoder is None:
        return default_encoder(fmt)
    if encoder not in ENCODERS:
        raise ConfigError(None, "views.encode.encoder", f"{encoder!r}: must be one of {', '.join(ENCODERS)}")
    if fmt not in ENCODERS[encoder]:
        raise ConfigError(None, "views.encode.encoder", f"{encoder} does not write {fmt}; use "
                          f"{' or '.join(n for n, f in ENCODERS.items() if fmt in f)}")
    if _module(encoder) is None:
        raise ConfigError(None, "views.encode.encoder", f"{encoder} is not installed: pip install {PACKAGES[encoder]}")
    return encoder


def _check_images(images) -> np.ndarray:
    images = np.asarray(images)
    if images.dtype != np.uint8:
        raise ConfigError(None, "views.encode.images", f"images must be uint8, got {images.dtype}")
    if images.ndim != 4 or images.shape[-1] != 3 or 0 in images.shape[1:]:
        raise ConfigError(None, "views.encode.images", f"images must be (R, H, W, 3) RGB, got shape {images.shape}")
    return np.ascontiguousarray(images)


def _pool(threads: int) -> ThreadPoolExecutor:
    with _LOCK:
        if threads not in _POOLS:
            _POOLS[threads] = ThreadPoolExecutor(threads, thread_name_prefix="ignjax-encode")
        return _POOLS[threads]


def encode_images(images, fmt: str = "jpeg", quality: int = 90, *, encoder: str | None = None,
                  threads: int | None = None) -> list[bytes]:
    """Encode a batch of images, in order.

    Args:
        images: (R, H, W, 3) uint8 RGB.
        fmt: "jpeg" (or "jpg") or "png".
        quality: JPEG quality 1..100 (checked but unused for PNG).
        encoder: "pillow", "simplejpeg" or "opencv"; None for
            :func:`default_encoder`.
        threads: encoding threads; default ``min(4, os.cpu_count())``.

    Returns:
        R byte strings, image i at index i.

    Raises:
        ConfigError: naming the bad field: ``views.encode.format``,
            ``views.encode.quality``, ``views.encode.encoder`` (unknown,
            wrong format, or not installed: the message says what to pip
            install), ``views.encode.threads`` or ``views.encode.images``
            (not uint8 or not (R, H, W, 3)).
    """
    fmt = _check_format(fmt)
    if isinstance(quality, bool) or not isinstance(quality, (int, np.integer)) or not 1 <= quality <= 100:
        raise ConfigError(None, "views.encode.quality", f"{quality!r}: must be an integer in 1..100")
    quality = int(quality)
    encode = _ENCODE[_check_encoder(encoder, fmt)]
    if threads is None:
        threads = min(4, os.cpu_count() or 1)
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ConfigError(None, "views.encode.threads", f"{threads!r}: must be a positive integer")
    images = _check_images(images)
    if threads == 1 or len(images) <= 1:
        return [encode(img, fmt, quality) for img in images]
    return list(_pool(int(threads)).map(lambda img: encode(img, fmt, quality), images))


def data_url(b: bytes, fmt: str) -> str:
    """``data:image/<fmt>;base64,...`` of encoded image bytes, for an
    OpenAI-style ``{"type": "image_url", "image_url": {"url": ...}}``."""
    return f"data:{_MIME[_check_format(fmt)]};base64,{base64.b64encode(bytes(b)).decode('ascii')}"


__all__ = ["encode_images", "data_url", "available_encoders", "default_encoder", "FORMATS", "ENCODERS", "PREFERRED",
           "PACKAGES", "PNG_COMPRESS_LEVEL"]
