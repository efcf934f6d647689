"""*Record clip* and *Download report* in the Player, Control and Planner tabs of one browser tab.

A folder of widgets (clip size from :data:`tpm_viz.media.clips.SIZE_PRESETS`, GIF or MP4, frame rate) with the two
buttons and a progress line. The tab's view passes a function that returns its current :class:`Material` (or None:
nothing to take out yet). *Record clip* takes the tab's camera as it is at the click (:func:`tab_camera`: the clip
is the tab's own 3D view, whatever the view does meanwhile), one of the server's recording slots, and records in the
fair worker, a few frames per job (:class:`~.recording.Recording`), writing its progress under the buttons; the
file goes to this browser as a download (viser's ``send_file_download``). The page stays usable meanwhile; one clip
per tab at a time (a second click is refused with one line, so is a click when every slot of the server is busy).
*Download report* writes the lab report (:func:`tpm_viz.media.report.report_html`) in the tab's language, in the
worker. A tab that closes drops its pending job; the slot comes back when the recording ends in any way.
"""

from __future__ import annotations

import datetime
import math

import viser

from tpm_viz.classroom.guard import guarded
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.markup import html
from tpm_viz.core.words import Phrase, T, say
from tpm_viz.media.clips import DEFAULT_FPS, SIZE_PRESETS
from tpm_viz.media.report import report_html
from tpm_viz.media.views3d import Camera
from tpm_viz.ui.teaching.takeout.materials import control_material, planner_material, player_material
from tpm_viz.ui.teaching.takeout.recording import SLOTS, Material, Recording
from tpm_viz.ui.worded import TabGui, Worded

__all__ = ["FORMATS", "MATERIALS", "RATES", "TakeOut", "tab_camera", "takeout_for"]

FORMATS = {"GIF": "gif", "MP4 (H.264)": "mp4"}
RATES = ("10", "20", "25", "30")
"""Frame rates offered [frames/s]: each frame is one run sample, played at this rate."""
MATERIALS = {"player": player_material, "control": control_material, "planner": planner_material}
"""The material of each teaching tab's view (:mod:`.materials`)."""


def tab_camera(client: viser.ClientHandle) -> Camera:
    """The tab's camera as its page last reported it (viser's ``client.camera``: pose, vertical field of view and
    the canvas's aspect ratio); one-line :class:`InputError` while it is not known."""
    try:
        camera = client.camera
        width, height = camera.image_width, camera.image_height
        aspect = width / height if width > 0 and height > 0 else math.nan
        position, wxyz, fov = tuple(camera.position.tolist()), tuple(camera.wxyz.tolist()), float(camera.fov)
    except AssertionError:  # no camera message yet
        position, wxyz, fov, aspect = (math.nan,) * 3, (math.nan,) * 4, math.nan, math.nan
    return Camera(position, wxyz, fov, aspect)


def _internal_error(owner, exc: Exception) -> None:
    owner.view.refuse(Phrase("internal error ({kind}), logged on the server", kind=type(exc).__name__), resync=False)


class TakeOut:
    """The clip and report widgets of one tab's Player, Control or Planner (``where``: a key of the worker)."""

    def __init__(self, view, worker, material, where: str) -> None:
        self.view = view
        self.worker = worker
        self.material = material
        self.where = where
        self.recording: Recording | None = None
        self.reporting = False
        self.line: Worded | None = None

    def build(self, gui: TabGui) -> None:
        """The folder of widgets (inside the tab's context)."""
        with gui.add_folder("Clip and report", expand_by_default=False):
            self.size = gui.add_dropdown("Clip size", tuple(SIZE_PRESETS), initial_value="800×450")
            self.format = gui.add_dropdown("Clip format", tuple(FORMATS), initial_value="GIF")
            self.rate = gui.add_dropdown("Frames per second", RATES, initial_value=str(DEFAULT_FPS))
            self.record = gui.add_button(
                "Record clip", icon=viser.Icon.MOVIE, hint="One frame per sample of the run, with the time and forces"
            )
            self.report = gui.add_button("Download report", icon=viser.Icon.REPORT, color="gray")
            self.line = gui.add_html("")
        self.record.on_click(self._on_record)
        self.report.on_click(self._on_report)

    def _tell(self, phrase: Phrase | None) -> None:
        """The progress line (any thread)."""
        with self.view.hub.locked():
            if self.line is not None and not self.view.closed:
                text = "" if phrase is None else say(self.view.lang, phrase)
                self.line.content = html('<p style="margin:0;font-size:0.85em">{text}</p>', text=text) if text else ""

    def _refuse(self, what) -> None:
        with self.view.hub.locked():
            if not self.view.closed:
                self.view.refuse(what, resync=False)

    def _current(self) -> Material:
        material = self.material()
        if material is None:
            raise InputError(T("nothing to record yet: load or compute a run first"))
        return material

    # -- the clip --------------------------------------------------------------------------------------------
    @guarded(on_error=_internal_error)
    def _on_record(self, event) -> None:
        if getattr(event, "client", None) is None or self.view.closed:
            return
        try:
            self._start_clip()
        except TpmVizError as exc:
            self._refuse(exc)

    def _start_clip(self) -> None:
        with self.view.hub.locked():
            if self.recording is not None:
                raise InputError(T("a clip is already being recorded in this tab: wait for it to finish"))
            size = SIZE_PRESETS.get(self.size.value, SIZE_PRESETS["800×450"])
            fmt = FORMATS.get(self.format.value, "gif")
            fps = int(self.rate.value) if self.rate.value in RATES else DEFAULT_FPS
            material = self._current()
            camera = tab_camera(self.view.client)
            if not SLOTS.acquire(blocking=False):
                raise InputError(T("the server is recording other clips: try again in a moment"))
            self.recording = Recording(material, size, fmt, fps, camera)
        self._tell(T("Recording the clip…"))
        self._next(self.recording)

    def _next(self, recording: Recording) -> None:
        submitted = self.worker.submit(
            ("clip", self.where),
            recording.step,
            lambda finished, error: self._stepped(recording, finished, error),
            tab=self.view,
            dropped=lambda: self._end(recording, None),
        )
        if not submitted:
            self._end(recording, T("the server is busy with other tabs' computations: try again in a moment"))

    def _stepped(self, recording: Recording, finished, error) -> None:
        if error is not None or self.view.closed:
            self._end(recording, error)
            return
        if not finished:
            self._tell(
                Phrase("Recording the clip: {done} of {total} frames", done=recording.done, total=recording.total)
            )
            self._next(recording)
            return
        data = recording.data or b""
        self._end(recording, None)
        self.view.client.send_file_download(recording.name, data, save_immediately=True)
        self._tell(Phrase("Clip ready: {name}, {kib} KiB", name=recording.name, kib=len(data) // 1024))

    def _end(self, recording: Recording, error) -> None:
        """The recording is over (finished, refused, failed, dropped): its canvas, encoder and slot go back."""
        recording.close()
        with self.view.hub.locked():
            if self.recording is not recording:
                return
            self.recording = None
        SLOTS.release()
        if error is not None:
            self._tell(Phrase("Clip not recorded: {why}", why=_words(error)))
            self._refuse(error)
        elif recording.data is None:
            self._tell(None)

    # -- the report ------------------------------------------------------------------------------------------
    @guarded(on_error=_internal_error)
    def _on_report(self, event) -> None:
        if getattr(event, "client", None) is None or self.view.closed:
            return
        try:
            self._start_report()
        except TpmVizError as exc:
            self._refuse(exc)

    def _start_report(self) -> None:
        with self.view.hub.locked():
            if self.reporting:
                raise InputError(T("the report is being written: wait for it to finish"))
            material = self._current()
            lang = self.view.lang
            self.reporting = True

        def write() -> tuple[str, bytes]:
            run, sections = material.report()
            today = datetime.datetime.now(datetime.UTC).date()
            return f"{material.stem}-report.html", report_html(run, lang, today, sections).encode("utf-8")

        self._tell(T("Writing the report…"))
        if not self.worker.submit(
            ("report", self.where), write, self._reported, tab=self.view, dropped=lambda: self._reported(None, None)
        ):
            self._reported(
                None, InputError(T("the server is busy with other tabs' computations: try again in a moment"))
            )

    def _reported(self, result, error) -> None:
        with self.view.hub.locked():
            self.reporting = False
        if self.view.closed:
            return
        if error is not None:
            self._tell(Phrase("Report not written: {why}", why=_words(error)))
            self._refuse(error)
            return
        if result is None:
            self._tell(None)
            return
        name, data = result
        self.view.client.send_file_download(name, data, save_immediately=True)
        self._tell(Phrase("Report ready: {name}", name=name))


def _words(error) -> Phrase | str:
    """The words of a refusal, or that a bug was logged."""
    if isinstance(error, TpmVizError):
        return error.args[0] if error.args and isinstance(error.args[0], Phrase) else str(error)
    if isinstance(error, Phrase):
        return error
    return Phrase("internal error ({kind}), logged on the server", kind=type(error).__name__)


def takeout_for(view, worker, owner, where: str, gui: TabGui) -> TakeOut:
    """The clip and report widgets for ``owner`` (the Player, Control or Planner view of ``view``, ``where`` =
    ``"player"``, ``"control"`` or ``"planner"``), built at the end of its tab."""
    material = MATERIALS[where]
    takeout = TakeOut(view, worker, lambda: material(owner), where)
    takeout.build(gui)
    return takeout
