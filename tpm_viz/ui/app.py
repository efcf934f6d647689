"""The browser app: a viser server on 127.0.0.1, one :class:`ClientView` per tab, one shared mechanism.

``main(host, port, presenter_token=None)`` is what ``python app.py`` and ``tpm-viz serve`` call. It prints
exactly one line with the URL the server really got (viser moves to the next port when one is busy) and serves
until Ctrl-C; problems go to the ``tpm_viz.ui`` logger (stderr).

Safety: the default host is loopback, and a warning is printed for any other address. viser's share-URL tunnel (an
outside relay that a client can request even with the button hidden) is disabled by replacing
``server.request_share_url`` with a no-op. Malformed GUI updates and uploads larger than
:data:`~tpm_viz.app.inputs.MAX_UPLOAD_BYTES` are dropped before viser handles them (:mod:`.transport`). With a presenter
token only the presenter's tab changes the shared mechanism (:mod:`.access`). Connect and disconnect handlers are
guarded (:mod:`.guard`): one bad tab never stops the server.
"""

from __future__ import annotations

import logging
import signal
import sys
import threading
import time
import warnings
import weakref
from collections.abc import Callable, Sequence
from pathlib import Path

import viser

from tpm_viz import multibody
from tpm_viz.app.lessons import Demo, load_lessons
from tpm_viz.app.readouts import Reference
from tpm_viz.app.state import AppState
from tpm_viz.classroom.access import Access
from tpm_viz.classroom.guard import guarded, log, log_fault, report
from tpm_viz.classroom.identity import Keys
from tpm_viz.classroom.launches import Plug, Tickets
from tpm_viz.classroom.network import HostRules, Network, is_loopback
from tpm_viz.classroom.runtime import tune_for_serving
from tpm_viz.classroom.session import Hub
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, Phrase, say
from tpm_viz.ui.announce import nobody, serving
from tpm_viz.ui.classroom import Classroom, Handshakes, local_addresses
from tpm_viz.ui.client import ClientView
from tpm_viz.ui.continuity import LectureStore, lecture_store
from tpm_viz.ui.graded import grade_launches
from tpm_viz.ui.guide import Guides
from tpm_viz.ui.keyboard import keyboard_of
from tpm_viz.ui.launched import Launched
from tpm_viz.ui.login import LoginPanel
from tpm_viz.ui.look import dock_panel
from tpm_viz.ui.phone import is_touch
from tpm_viz.ui.room import Room
from tpm_viz.ui.scene import MechanismScene, camera_pose
from tpm_viz.ui.share import ShareDesk
from tpm_viz.ui.teaching.exercises.desk import ExerciseDesk
from tpm_viz.ui.teaching.tabs import Services
from tpm_viz.viserkit.adapter import install, new_server
from tpm_viz.viserkit.core import connection_request
from tpm_viz.viserkit.limits import DEFAULT_MAX_CONNECTIONS, DEFAULT_MAX_PER_ADDRESS, set_admission, set_max_connections
from tpm_viz.viserkit.transport import harden

__all__ = ["TpmApp", "build_server", "main"]

BRAND = (13, 148, 136)
CLASS_INFO_DELAY = 0.3
"""A change of the class (tabs joining, leaving, switching) is shown in every tab's classroom line after this many
seconds per 30 tabs (at least this), once for all the changes meanwhile [s]."""


def build_server(
    host: str = "127.0.0.1",
    port: int = 8080,
    hosts: HostRules | None = None,
    keys: Keys | None = None,
    tickets: Tickets | None = None,
    per_address: int = DEFAULT_MAX_PER_ADDRESS,
) -> viser.ViserServer:
    """A quiet viser server: no share tunnel, no environment map or shadows (fast first paint). ``hosts``: the
    ``Host`` names it answers to and the trusted proxies (default: this machine's names and addresses, no proxy);
    ``keys``: the identity cookies' keys (default: the process's, :data:`~.classroom.DEFAULT_KEYS`); ``tickets``: the
    LTI launches' (``serve --lti``); ``per_address``: the most tabs from one network address
    (:mod:`tpm_viz.viserkit.admission`).

    Raises :class:`~tpm_viz.viserkit.core.IncompatibleViserError` (one line) if the installed viser is not the tested
    one.
    """
    handshakes = Handshakes(hosts or HostRules(addresses=local_addresses, bound=host), keys, tickets=tickets)
    server = new_server(handshake=handshakes, host=host, port=port, label="tpm-viz", verbose=False)  # same-origin
    keyboard_of(server, handshakes.keyboard)  # the page script's keys reach this server's tabs (ui/keyboard.py)
    install(server)  # viser's patches on this server, in viserkit/PATCHES.md's order (viserkit/adapter.py)
    set_admission(server, max_per_address=per_address)  # one student's sockets never lock the class out
    server.gui.configure_theme(
        control_width="large", show_share_button=False, show_logo=False, brand_color=BRAND, dark_mode=False
    )
    dock_panel(server.gui)  # the panel beside the canvas, never over the mechanism (ui/look.py)
    server.scene.configure_environment_map(None)
    server.scene.configure_default_lights(enabled=True, cast_shadow=False)
    server.scene.add_light_hemisphere(
        "/lights/sky", sky_color=(255, 255, 255), ground_color=(148, 163, 184), intensity=1.4
    )
    server.scene.add_light_directional("/lights/key", intensity=1.2, position=(0.4, -0.6, 1.5))
    server.scene.world_axes.visible = False
    return server


class TpmApp:
    """The app on one server: the hub (shared state, lock) and a view per connected tab."""

    def __init__(
        self,
        server: viser.ViserServer,
        params: Params | None = None,
        reference: Reference | None = multibody.inverse_dynamics,
        presenter_token: str | None = None,
        max_connections: int = DEFAULT_MAX_CONNECTIONS,
        classroom: Classroom | None = None,
        store: LectureStore | None = None,
        lessons: tuple[Sequence[Demo], Sequence[str]] | None = None,
        lti: Plug | None = None,
    ) -> None:
        self.server = server
        set_max_connections(server, max_connections)  # the next tab is told the class is full, then closed
        set_admission(server, classroom.lecturer_address if classroom else None)  # the lecturer's: never crowded out
        token = presenter_token if presenter_token or classroom is None or lti else classroom.token
        self.access = Access(token, required=lti is not None)  # --lti: an instructor's launch presents
        self.lti = lti
        self.launched = None if lti is None else Launched(self, lti.tickets)
        """Tabs that arrive from the LMS (:mod:`.launched`), or None without ``--lti``."""
        state = AppState.initial(params)
        shared_scene = MechanismScene(server.scene, state.params, sink=server)  # drawn once for every tab
        self.hub = Hub(state, reference, self.access, shared_scene)
        self.hub.evaluate(self.hub.shared.state)  # warm-up: builds the Pinocchio model once
        self.services = Services.create(self.hub) if lessons is None else Services.create(self.hub, *lessons)
        """The worker, floor maps and trajectory runs every tab of this app shares."""
        self.views: dict[int, ClientView] = {}
        self.arrived: weakref.WeakSet[ClientView] = weakref.WeakSet()
        """The views whose connection is fully handled (keys, classroom, guide, share link, class line)."""
        self._views_lock = threading.Lock()
        self._gone: weakref.WeakSet[ClientView] = weakref.WeakSet()  # tabs that left, until their garbage is freed
        self._class_info_timer: threading.Timer | None = None
        position, look_at = camera_pose(self.hub.shared.state.params)
        server.initial_camera.position = position
        server.initial_camera.look_at = look_at
        self.hub.on_membership = self._class_info
        self.room = Room(self, classroom, store)
        """Classroom mode, tabs that come back, the session file (:mod:`.room`)."""
        self.room.start()
        self.exercises = self.services.exercises = ExerciseDesk(
            self.hub, self.services, self._tabs, self.room.reads_results
        )
        """Gradebook, students, results; ``.score_sink``: LTI's hook (:mod:`.teaching.exercises.desk`)."""
        self.exercises.start(self.room.store)
        self.graded = None if self.launched is None else grade_launches(self)
        """A launch's exercise opened in its tab, its score back to the course (:mod:`.graded`), or None."""
        self.room.lecturer_hooks.append(self.exercises.lecturer_added)
        self.guides = Guides(self.room.store)
        """Which browsers dismissed the first visit's guide (:mod:`.guide`)."""
        self.shares = ShareDesk(self.hub, lambda: self.room.store.store, lambda: self.room.urls)
        """Share links: *Copy share link* and the link a tab's page was opened with (:mod:`.share`)."""
        self.keyboard = keyboard_of(server)
        """The tabs' keys: arrows move the platform, Q/A and W/S the sliders (:mod:`.keyboard`)."""
        server.on_client_connect(self._connect)
        server.on_client_disconnect(self._disconnect)

    @property
    def port(self) -> int:
        """The port the server really listens on."""
        return self.server.get_port()

    @guarded
    def _connect(self, client: viser.ClientHandle) -> None:
        harden(client, lang=lambda: self._lang_of(client.client_id))  # malformed updates and big uploads dropped
        who = self.room.identify(client)  # before the view moves the camera
        who, launch, fresh = (who, None, False) if self.launched is None else self.launched.arrive(client, who)
        view = self.room.build(who, lambda saved: ClientView(client, self.hub, self.services, saved=saved))
        if self.access.enabled:
            view.login = LoginPanel(view.gui, lambda event, view=view: self._login(event, view))
        with self._views_lock:
            self.views[client.client_id] = view
        self.keyboard.join(view)
        self.room.connected(view, who)  # presenter or not; what it had before a drop
        if self.launched is not None:
            self.launched.connected(view, launch, fresh)  # an LMS launch: presenter or student, its lesson
        self.exercises.connected(view, who[0])  # the student's numbers and attempts (ui/teaching/exercises/)
        self.guides.greet(view, who[0])  # the first visit's guide, unless this browser dismissed it (ui/guide.py)
        self.shares.connected(view, connection_request(self.server, client.client_id))  # a link: its own copy
        view.scene.set_touch(is_touch(connection_request(self.server, client.client_id)))  # a phone (ui/phone.py)
        self._class_info()
        self.arrived.add(view)

    def _tabs(self) -> list[ClientView]:
        with self._views_lock:
            return list(self.views.values())

    def _lang_of(self, client_id: int) -> Lang:
        """The language of a tab (English until its view is built)."""
        with self._views_lock:
            view = self.views.get(client_id)
        return Lang.EN if view is None else view.lang

    @guarded
    def _disconnect(self, client: viser.ClientHandle) -> None:
        with self._views_lock:
            view = self.views.get(client.client_id)
        if view is not None:
            self.room.leaving(view)  # kept 30 minutes for a tab that comes back: kept before the tab is gone
            with self._views_lock:
                self.views.pop(client.client_id, None)
            self.keyboard.leave(view)
            self.exercises.leaving(view)
            self.access.logout(view)
            view.close()
            self._gone.add(view)
            if self.services.later is not None:  # its garbage freed at the next quiet moment, not in the next storm
                self.services.later.tidy(kept=lambda: len(self._gone))

    @guarded
    def _login(self, event, view: ClientView) -> None:
        """*Log in as presenter*: check the typed token (cleared at once) and tell this tab only."""
        if getattr(event, "client", None) is None or view.closed:
            return
        login = view.login
        if login is None:
            return
        attempt = login.take()
        try:
            ok = self.access.login(view, attempt, source=self.room.source(view))
        except TpmVizError as exc:
            view.refuse(exc, resync=False)
            return
        if not ok:
            log_fault(view.client.client_id, "login", "wrong presenter token")  # rate-limited
            view.refuse("wrong presenter token", resync=False)
            return
        log.info("client %s is now a presenter tab", view.client.client_id)
        login.show("**You are the presenter**: your changes go to the shared mechanism.")
        self.room.promoted(view)
        self._class_info()

    def _class_info(self) -> None:
        """Tabs joined, left, switched or logged in: redraw every tab's classroom line, at most once per
        :data:`CLASS_INFO_DELAY` per 30 tabs (150 tabs arriving or leaving at once redraw 150 lines a few times, not
        150 x 150 times)."""
        with self._views_lock:
            if self._class_info_timer is not None:
                return
            delay = CLASS_INFO_DELAY * max(1.0, len(self.views) / 30)
            self._class_info_timer = timer = threading.Timer(delay, self._write_class_info)
        timer.daemon = True
        timer.start()

    @guarded
    def _write_class_info(self) -> None:
        with self._views_lock:
            self._class_info_timer = None
        connected = set(self.server.get_clients())
        with self._views_lock:
            views = [v for cid, v in self.views.items() if not v.closed and cid in connected]
        tabs, shared = len(views), self.hub.shared_viewers()
        count = (  # English has a singular (Korean counts both alike)
            Phrase("{tabs} tab connected, {shared} on the shared mechanism.", tabs=tabs, shared=shared)
            if tabs == 1
            else Phrase("{tabs} tabs connected, {shared} on the shared mechanism.", tabs=tabs, shared=shared)
        )
        if self.lti is not None and self.lti.tickets.course:  # the class label: the LMS course's title
            count = Phrase("Course: {course}. {count}", course=self.lti.tickets.course, count=count)
        for view in views:
            if not view.session.shared:
                parts = [count, Phrase("You see your own copy.")]
            else:
                parts = [count, Phrase("You see the shared mechanism.")]
            if self.access.enabled and self.access.open_to_class:
                parts.append(Phrase("Presenter mode: the presenter handed the shared mechanism to the class."))
            elif self.access.enabled and self.access.is_presenter_tab(view):
                parts.append(Phrase("Presenter mode: you are allowed to change the shared mechanism."))
            elif self.access.enabled:
                parts.append(Phrase("Presenter mode: only the presenter is allowed to change the shared mechanism."))
            view.set_class_info(" ".join(say(view.lang, part) for part in parts))

    def stop(self) -> None:
        """Stop the server (the port is free again at once) and the app's drag threads; save the session."""
        with self._views_lock:
            if self._class_info_timer is not None:
                self._class_info_timer.cancel()
        self.exercises.stop()
        self.room.stop()
        if self.lti is not None:
            self.lti.stop()
        self.server.stop()
        self.hub.drag_pool.shutdown(wait=False, cancel_futures=True)


def _log_to_stderr() -> None:
    """Send the app's log (refusals of uploads, failed callbacks and threads with tracebacks) to stderr, once."""
    logger = logging.getLogger("tpm_viz")
    if not logger.handlers:
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
        logger.addHandler(handler)
        logger.setLevel(logging.INFO)
    threading.excepthook = _thread_died


def _thread_died(args) -> None:
    """A background thread (playback, worker) that dies of a bug: its traceback goes to the same log, counted."""
    if not issubclass(args.exc_type, SystemExit):
        report(args.exc_value, f"thread {args.thread.name if args.thread else '?'}")


def main(
    host: str = "127.0.0.1",
    port: int = 8080,
    block: bool = True,
    presenter_token: str | None = None,
    classroom: bool = False,
    session: Path | None = None,
    fresh: bool = False,
    addresses: Callable[[], list[str]] | None = None,
    lessons: str | Path | None = None,
    trusted_proxies: Sequence[str] = (),
    allowed_hosts: Sequence[str] = (),
    lti: Plug | None = None,
    tabs_per_address: int = DEFAULT_MAX_PER_ADDRESS,
) -> TpmApp:
    """Serve the app; print the real URL; block until Ctrl-C (or SIGTERM) unless ``block`` is False.

    ``presenter_token``: if given, only a tab that logs in with it changes the shared mechanism. ``classroom``
    (implied by a non-loopback ``host``): print the URLs students type and a QR code, a tab on this machine is the
    presenter, and a token (``presenter_token`` or a random one, printed here only) lets the lecturer present from
    another device. ``session``: the store to read at start and keep saved (None: nothing is saved; a JSON session
    file is imported once into a store beside it: :mod:`.continuity`); ``fresh``: start clean (the store is set
    aside, never overwritten). ``addresses``: this machine's network addresses (a lookup;
    tests inject theirs). ``lessons``: a folder of lesson files (or one file) for the *Demos* tab instead of the
    packaged ones; a refused file is one warning line, and no lesson at all is an error. ``trusted_proxies``: the
    reverse proxies whose X-Forwarded-For / Forwarded name the client; ``allowed_hosts``: more ``Host`` names to
    answer to (:mod:`tpm_viz.classroom.network`); ``tabs_per_address``: the most tabs from one network address
    (:mod:`tpm_viz.viserkit.admission`); ``lti``: serve as an LTI tool too (``--lti``: docs/lti.md)."""
    access = Access(presenter_token)  # validates the token before anything starts
    if lti is not None and session is None:
        raise InputError("--lti keeps the LMS users and grades in the session store: give --session FILE")
    network = Network.of(trusted_proxies, allowed_hosts)
    tour = None if lessons is None else load_lessons(lessons)
    if tour is not None:
        if not tour[0]:
            raise InputError(f"no lesson loaded from {lessons}: {tour[1][0] if tour[1] else 'no lesson files'}")
        for problem in tour[1]:
            print(f"warning: lesson refused: {problem}", file=sys.stderr)
    classroom = classroom or not is_loopback(host)
    room = Classroom(addresses=addresses or local_addresses) if classroom else None
    if room is not None and lti is not None:
        room.presenter_address = nobody  # --lti: this computer presents by a launch or the token only
    if room is not None and presenter_token:
        room.token = presenter_token
    if not is_loopback(host):
        who = "the presenter (token) can" if access.enabled or classroom else "anyone who can reach this address can"
        print(
            f"warning: serving on {host}, not only this machine: {who} change the shared mechanism "
            "(no encryption: use a trusted network)",
            file=sys.stderr,
        )
    _log_to_stderr()
    # A tab that closes while its frame is being pushed makes viser warn once per connection; expected in a
    # classroom (the tab is dropped a moment later), and not worth a line in the log each time.
    warnings.filterwarnings("ignore", message=r"Queued a \w+ on a closed connection", category=UserWarning)
    store = None if room is None and session is None else lecture_store(session, fresh)
    if store is not None:
        store.open()  # its notices, and the cookie keys kept beside it, before the first page
    keys = None if store is None else store.keys
    tickets = None if lti is None else lti.tickets
    hosts = HostRules(network, addresses or local_addresses, bound=host)
    server = build_server(host, port, hosts, keys, tickets, tabs_per_address)
    app = TpmApp(server, presenter_token=presenter_token, classroom=room, store=store, lessons=tour, lti=lti)
    if store is not None:
        store.serving(app.port)  # a second server on this store is refused naming this port (classroom/storelock.py)
    tune_for_serving()  # the collector and the threads' turns of a serving process (classroom/runtime.py)
    if not block:
        serving(app, host, room)
        return app
    signal.signal(signal.SIGTERM, _interrupt)  # before the URL is printed: a stop right after it saves too
    try:
        serving(app, host, room)
        while True:  # short sleeps: a signal delivered to another thread does not cut the main thread's sleep,
            time.sleep(0.5)  # and Python runs the handler only when the main thread runs again
    except KeyboardInterrupt:
        pass
    finally:
        app.stop()
    return app


def _interrupt(signum, frame) -> None:
    raise KeyboardInterrupt
