"""The store's record bodies: the lecture, a browser's tabs, and the one-time import of an old JSON session file.

A mechanism is the JSON form of :func:`tpm_viz.classroom.sessionfile.encode_saved`, except that an uploaded trajectory's
samples are a blob of the store (``{"kind": "csv", "blob": <sha256>, ...}``): nine students with the same 540 kB
CSV keep it once. Reading goes through :func:`tpm_viz.classroom.sessionfile.decode_saved` (the library's own checks); a
record that fails is skipped by the caller, a missing blob only drops that trajectory.

:class:`Records` is the codec of one store (it remembers which trajectories it has put, so that a save does not
encode a 20,000-row CSV again every two seconds). :func:`import_json` imports a session file of tpm-viz's JSON
format (version 1) once per content: the lecture and its lesson step; the remembered tabs of that file are not
imported, their cookies were not signed by this server (:mod:`.identity`).
"""

from __future__ import annotations

import hashlib
import json
import weakref
from collections import OrderedDict
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from tpm_viz.app.runs import Source
from tpm_viz.classroom import sessionfile
from tpm_viz.classroom.sessionfile import Document, Saved
from tpm_viz.classroom.store import Copy, Store
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.files import loads_json, read_bytes

__all__ = ["Records", "import_json"]

_REMEMBERED_SOURCES = 512


class Records:
    """Encode and decode the record bodies of ``store`` (thread-safe enough: called under the app's lock)."""

    def __init__(self, store: Store) -> None:
        self.store = store
        self._put: OrderedDict[int, tuple[weakref.ref[Source], str]] = OrderedDict()
        """id(source) -> (the source, weakly: remembering a digest never keeps 480 kB of samples alive; digest)."""

    # -- writing ------------------------------------------------------------------------------------------------
    def _digest(self, source: Source, samples: dict[str, Any]) -> str:
        known = self._put.get(id(source))
        if known is not None and known[0]() is source:
            self._put.move_to_end(id(source))
            return known[1]
        data = json.dumps(samples, allow_nan=False).encode()
        digest = self.store.put_blob(data)
        self._put[id(source)] = (weakref.ref(source), digest)
        while len(self._put) > _REMEMBERED_SOURCES:
            self._put.popitem(last=False)
        return digest

    def saved(self, saved: Saved) -> dict[str, Any]:
        """The JSON form of one mechanism, an uploaded trajectory's samples put in a blob."""
        body = sessionfile.encode_saved(saved)
        trajectory = body.get("trajectory")
        if saved.source is not None and isinstance(trajectory, dict) and "t" in trajectory:
            samples = {"t": trajectory.pop("t"), "p": trajectory.pop("p", [])}
            trajectory["blob"] = self._digest(saved.source, samples)
        return body

    def lecture(self, doc: Document) -> dict[str, Any]:
        """The lecture's record: the shared mechanism and the lesson step."""
        return {"shared": self.saved(doc.shared), "lesson_step": int(doc.lesson_step)}

    def copies(self, doc: Document) -> dict[str, Copy]:
        """One record per browser of ``doc.tabs`` (each record dict may carry its ``address``)."""
        out = {}
        for key, records in doc.tabs.items():
            body = [
                {
                    "private": bool(r["private"]),
                    "presenter": bool(r.get("presenter", False)),
                    "left_at": float(r["left_at"]),
                    "saved": None if r.get("saved") is None else self.saved(r["saved"]),
                }
                for r in records
            ]
            address = str(records[0].get("address", "")) if records else ""
            out[key] = Copy(address, max((float(r["left_at"]) for r in records), default=0.0), {"tabs": body})
        return out

    # -- reading ------------------------------------------------------------------------------------------------
    def _mechanism(self, raw: Any) -> Saved:
        if isinstance(raw, dict) and isinstance(raw.get("trajectory"), dict) and "blob" in raw["trajectory"]:
            trajectory = dict(raw["trajectory"])
            data = self.store.get_blob(str(trajectory.pop("blob")))
            samples = None if data is None else _json(data)
            if isinstance(samples, dict) and "t" in samples and "p" in samples:
                trajectory.update(t=samples["t"], p=samples["p"])
                raw = dict(raw, trajectory=trajectory)
            else:
                raw = dict(raw, trajectory=None)  # the samples are gone: the mechanism without its trajectory
        return sessionfile.decode_saved(raw)

    def read_lecture(self, body: Any, steps: int | None = None) -> tuple[Saved, int]:
        """The shared mechanism and the lesson step of a lecture record (raises a one-line InputError)."""
        if not isinstance(body, dict):
            raise InputError("session store: the lecture's record is not an object")
        step = body.get("lesson_step", 0)
        ok = isinstance(step, int) and not isinstance(step, bool) and 0 <= step < (steps or 1000)
        return self._mechanism(body.get("shared")), step if ok else 0

    def read_copies(self, copies: Mapping[str, Copy], now: float) -> tuple[dict[str, list[dict[str, Any]]], int]:
        """The tabs of every readable browser record still within :data:`~tpm_viz.classroom.sessionfile.KEEP_SECONDS`,
        and the number of records skipped."""
        tabs: dict[str, list[dict[str, Any]]] = {}
        skipped = 0
        for key, copy in copies.items():
            try:
                kept = []
                for r in copy.body["tabs"]:
                    left_at = float(r["left_at"])
                    if not now - sessionfile.KEEP_SECONDS <= left_at <= now + 60:
                        continue
                    saved = None if r.get("saved") is None else self._mechanism(r["saved"])
                    record = {"private": r.get("private") is True, "saved": saved, "left_at": left_at}
                    kept.append(dict(record, presenter=r.get("presenter") is True, address=copy.address))
            except (TpmVizError, TypeError, KeyError, ValueError, AttributeError):
                skipped += 1
                continue
            if kept:
                tabs[key] = kept
        return tabs, skipped


def _json(data: bytes) -> Any:
    try:
        return loads_json(data, "a stored trajectory")
    except InputError:
        return None


def import_json(store: Store, path: Path, records: Records) -> str | None:
    """Import the JSON session file ``path`` into ``store`` once (by its SHA-256): its lecture becomes the
    store's. Returns a one-line notice (imported, or why not), or None when there was nothing to do. ``path`` is
    never written."""
    try:
        data = read_bytes(path, sessionfile.MAX_DOCUMENT_BYTES)
    except InputError as exc:
        return f"session file not imported: {exc}"
    digest = hashlib.sha256(data).hexdigest()
    if store.imported(digest):
        return None
    try:
        doc = sessionfile.loads(data)
    except InputError as exc:
        store.mark_imported(digest, str(path))  # said once; the file is left as it is
        return f"{path} not imported ({exc}); it is left as it is"
    store.save(records.lecture(doc), {}, ())
    store.mark_imported(digest, str(path))
    tabs = loads_json(data, path).get("tabs")  # every remembered tab of the file, however old
    dropped = sum(len(v) for v in tabs.values() if isinstance(v, list)) if isinstance(tabs, dict) else 0
    extra = f"; {dropped} remembered tab(s) of it start afresh (their cookies were not issued by this server)"
    return f"imported the lecture of the session file {path} into the store" + (extra if dropped else "")
