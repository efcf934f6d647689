"""Encoders of a clip's frames: an animated GIF (Pillow) and an MP4 with H.264 (PyAV's bundled libx264).

Both are deterministic to the byte for the same frames: the GIF uses one palette taken from the first, middle
and last frames (no dithering); the MP4 is encoded on one thread with FFmpeg's bit-exact flags, so that neither
the encoder's threads nor its version string change the bytes. Both are bounded: at most
:data:`MAX_CLIP_BYTES`, checked while encoding. The writers take one frame at a time (the app records a clip in
short jobs, a few frames each); :func:`encode_clip` does it all at once.
"""

from __future__ import annotations

import contextlib
import io
import zlib
from collections.abc import Callable, Sequence
from fractions import Fraction

import av
import numpy as np
from PIL import Image

from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase

__all__ = ["FORMATS", "MAX_CLIP_BYTES", "ClipWriter", "GifWriter", "Mp4Writer", "clip_writer", "encode_clip"]

FORMATS = ("gif", "mp4")
MAX_CLIP_BYTES = 64 * 2**20
"""Largest clip [bytes]; a longer encoding stops with a one-line refusal."""
MP4_CRF = 23
"""x264's constant rate factor (quality: lower is better and larger)."""

Progress = Callable[[int, int], None]
FrameSource = Callable[[int], np.ndarray]


def _too_big(size: int) -> InputError:
    return InputError(
        Phrase(
            "the clip would be larger than {mib} MiB ({got} MiB so far): choose a smaller size or fewer samples",
            mib=MAX_CLIP_BYTES // 2**20,
            got=size // 2**20,
        )
    )


def _palette(samples: Sequence[np.ndarray]) -> Image.Image:
    """One palette of 255 colours for the whole clip, from a few of its frames side by side (the 256th is left
    for the transparent pixels that Pillow writes where a frame repeats the previous one)."""
    strip = Image.fromarray(np.concatenate(list(samples), axis=0))
    return strip.quantize(colors=255, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)


class _Bounded(io.BytesIO):
    """A buffer that refuses to grow beyond :data:`MAX_CLIP_BYTES`."""

    def write(self, data) -> int:
        if self.tell() + len(data) > MAX_CLIP_BYTES:
            raise _too_big(self.tell() + len(data))
        return super().write(data)


class GifWriter:
    """An animated GIF built one frame at a time: ``add(rgb)`` quantises a frame to the clip's palette (taken
    from ``samples``, e.g. its first, middle and last frames) and keeps it compressed; :meth:`finish` encodes.
    Delays in 10 ms steps; the GIF loops."""

    def __init__(self, fps: int, samples: Sequence[np.ndarray]) -> None:
        self.delay = max(10, round(100.0 / fps) * 10)  # ms, whole hundredths of a second
        self.palette = _palette(samples)
        self.size = (samples[0].shape[1], samples[0].shape[0])
        self._frames: list[bytes] = []
        self._kept = 0

    def add(self, rgb: np.ndarray) -> None:
        image = Image.fromarray(rgb).quantize(palette=self.palette, dither=Image.Dither.NONE)
        packed = zlib.compress(image.tobytes(), 1)
        self._kept += len(packed)
        if self._kept > MAX_CLIP_BYTES:
            raise _too_big(self._kept)
        self._frames.append(packed)

    def _images(self, start: int):
        for packed in self._frames[start:]:
            image = Image.frombytes("P", self.size, zlib.decompress(packed))
            image.putpalette(self.palette.getpalette() or [])
            yield image

    def finish(self) -> bytes:
        out = _Bounded()
        first = next(self._images(0))
        first.save(
            out, format="GIF", save_all=True, append_images=self._images(1), duration=self.delay, loop=0, optimize=True
        )
        return out.getvalue()


class Mp4Writer:
    """An MP4 (H.264, yuv420p, CRF :data:`MP4_CRF`) encoded as the frames come (``add``), closed by :meth:`finish`;
    the frame size must be even in both directions."""

    def __init__(self, fps: int, width: int, height: int) -> None:
        if width % 2 or height % 2:
            raise InputError(Phrase("an MP4 needs an even width and height, got {got}", got=f"{width}x{height}"))
        self._out = _Bounded()
        self._container = av.open(self._out, "w", format="mp4", options={"fflags": "+bitexact"})
        stream = self._container.add_stream("libx264", rate=Fraction(fps, 1))
        stream.width, stream.height, stream.pix_fmt = width, height, "yuv420p"
        stream.codec_context.thread_count = 1
        stream.codec_context.flags |= av.codec.context.Flags.bitexact
        stream.codec_context.options = {"crf": str(MP4_CRF), "preset": "medium", "threads": "1"}
        self._stream = stream

    def add(self, rgb: np.ndarray) -> None:
        try:
            self._container.mux(self._stream.encode(av.VideoFrame.from_ndarray(rgb, format="rgb24")))
        except BaseException:
            self.close()
            raise

    def finish(self) -> bytes:
        try:
            self._container.mux(self._stream.encode(None))
        finally:
            self.close()
        return self._out.getvalue()

    def close(self) -> None:
        """Release the encoder (idempotent); a clip abandoned half-way calls it."""
        with contextlib.suppress(Exception):
            self._container.close()


ClipWriter = GifWriter | Mp4Writer


def clip_writer(fmt: str, fps: int, frame: FrameSource, count: int) -> ClipWriter:
    """A writer of ``fmt`` (``"gif"`` or ``"mp4"``) for ``count`` frames ``frame(k)`` at ``fps`` frames/s."""
    if fmt == "gif":
        return GifWriter(fps, [frame(0), frame(count // 2), frame(count - 1)])
    if fmt == "mp4":
        height, width = frame(0).shape[:2]
        return Mp4Writer(fps, width, height)
    raise InputError(Phrase("a clip is a .gif or an .mp4 file, got {got}", got=repr(fmt)))


def encode_clip(fmt: str, frame: FrameSource, count: int, fps: int, progress: Progress | None = None) -> bytes:
    """The clip in ``fmt`` (``"gif"`` or ``"mp4"``) of ``frame(0) .. frame(count - 1)`` at ``fps`` frames/s."""
    writer = clip_writer(fmt, fps, frame, count)
    for k in range(count):
        writer.add(frame(k))
        if progress is not None:
            progress(k + 1, count)
    return writer.finish()
