"""Helpers for the offline lesson page's browser tests (tests/ui/test_takehome.py): opening a page with every other
request blocked, viser's player in the page's 3D view, where the platform is on the canvas, and the answers a
student might type (with what ``tpm-viz exercise grade`` says of each)."""

from __future__ import annotations

import contextlib
import io
import json
import math
from typing import Any, NamedTuple

import numpy as np
from PIL import Image

from tpm_viz.cli import main
from tpm_viz.drawing import meshes

VIEW = "#tpm-view"
FOV = 75.0 * math.pi / 180.0  # viser's initial camera (three.js' default vertical field of view)
PLATFORM_TOP = meshes.PLATFORM_Z[1]


class Opened(NamedTuple):
    context: Any
    page: Any
    requests: list[str]
    errors: list[str]


WATCH_POLICY = """
window.__cspViolations = [];
document.addEventListener("securitypolicyviolation", (e) => {
  window.__cspViolations.push(e.violatedDirective + " " + e.blockedURI);
});
"""
"""Init script (every frame, the 3D view's srcdoc too): the Content-Security-Policy violations of the document."""


def violations(page: Any) -> list[str]:
    """The policy violations of the page and of its 3D view (none may happen: the page needs nothing it forbids)."""
    return page.evaluate(
        """() => [...window.__cspViolations,
                  ...((document.getElementById('tpm-view') || {}).contentWindow?.__cspViolations || [])]"""
    )


def open_offline(browser: Any, url: str, viewport: tuple[int, int] = (1366, 768), view: bool = True) -> Opened:
    """``url`` in a fresh context where every request but the page itself is aborted and recorded; waits until the
    calculator and the panel are ready. ``view=False`` hides the 3D view once the page is ready (a test of the panel
    alone: SwiftShader's drawing on the page's main thread slows everything else down several times)."""
    context = browser.new_context(viewport={"width": viewport[0], "height": viewport[1]})
    requests: list[str] = []
    errors: list[str] = []

    def route(r: Any) -> None:
        requests.append(r.request.url)
        if r.request.url == url:
            r.continue_()
        else:
            r.abort()

    context.route("**/*", route)
    context.add_init_script(WATCH_POLICY)
    page = context.new_page()
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.goto(url)
    ready(page, view)
    return Opened(context, page, requests, errors)


def ready(page: Any, view: bool = True) -> None:
    """Wait until the page's calculator and panel are ready; hide its 3D view unless ``view``."""
    page.wait_for_function("window.tpm && window.tpmPage && window.tpmPage.calcReady === true", timeout=120_000)
    if not view:
        page.evaluate("document.getElementById('tpm-view').style.display = 'none'")


def click_center(page: Any, locator: Any) -> None:
    """A mouse click at the middle of ``locator`` (viser's widgets re-render every frame: a locator click waits for
    a stability that never comes)."""
    box = locator.bounding_box()
    page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)


def player(page: Any) -> Any:
    """viser's player bar in the 3D view."""
    return page.frame_locator(VIEW).locator(".mantine-Paper-root:has(.mantine-Slider-root)")


def pause(page: Any) -> None:
    """Pause viser's player (it plays and loops on load) and wait until its button says so."""
    button = player(page).locator("button").first
    icon = button.locator("svg")
    icon.wait_for(timeout=120_000)
    if "player-pause" in (icon.get_attribute("class") or ""):
        click_center(page, button)
    page.wait_for_function(
        """() => { const svg = document.getElementById('tpm-view').contentDocument
                .querySelector('.mantine-Paper-root button svg');
                return svg && svg.getAttribute('class').includes('player-play'); }""",
        timeout=60_000,
    )


def seek(page: Any, fraction: float) -> int:
    """Click viser's time slider at ``fraction`` of its track; wait until the panel follows the player's time to a
    frame and return that frame's index."""
    track = player(page).locator(".mantine-Slider-track")
    box = track.bounding_box()
    page.mouse.click(box["x"] + fraction * box["width"], box["y"] + box["height"] / 2)
    page.wait_for_function(
        """(f) => { const calc = tpmPage.calc; const t = calc.playerTime(); const T = tpmPage.data.frames.t.at(-1);
                return t !== null && Math.abs(t / T - f) < 0.05 && calc.state().frame === calc.frameAt(t); }""",
        arg=fraction,
        timeout=60_000,
    )
    return int(page.evaluate("tpmPage.calc.state().frame"))


def canvas_box(page: Any) -> dict[str, float]:
    """The 3D canvas (the largest of the view's canvases) in page coordinates."""
    boxes = [c.bounding_box() for c in page.frame_locator(VIEW).locator("canvas").all()]
    return max((b for b in boxes if b), key=lambda b: b["width"] * b["height"])


def project(camera: tuple[np.ndarray, np.ndarray], point: np.ndarray, width: float, height: float) -> np.ndarray:
    """Pixel (x, y) of the world point [m] (Z up) seen by a perspective camera at ``camera = (position, look_at)``
    with viser's field of view, on a canvas ``width x height``."""
    position, look_at = (np.asarray(v, float) for v in camera)
    forward = (look_at - position) / np.linalg.norm(look_at - position)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    v = np.asarray(point, float) - position
    depth = v @ forward
    t = math.tan(FOV / 2)
    ndc = np.array([(v @ right) / (depth * t * width / height), (v @ up) / (depth * t)])
    return np.array([(ndc[0] + 1) / 2 * width, (1 - ndc[1]) / 2 * height])


def canvas_image(page: Any) -> np.ndarray:
    """The 3D canvas as an RGB array (a screenshot of its box)."""
    return np.asarray(Image.open(io.BytesIO(page.screenshot(clip=canvas_box(page)))).convert("RGB"), dtype=float)


def window(image: np.ndarray, xy: np.ndarray, half: int) -> np.ndarray:
    x, y = (round(float(c)) for c in xy)
    return image[max(y - half, 0) : y + half + 1, max(x - half, 0) : x + half + 1].reshape(-1, 3)


def platform_at(image: np.ndarray, xy: np.ndarray) -> bool:
    """Whether the platform is drawn at pixel ``xy``: the yellow tool marker at ``P`` (a disc of 12 mm radius) in the
    middle of the dark platform top (slate, or red near the direct singularity); the floor is light everywhere."""
    ring = window(image, xy, 10)
    centre = window(image, xy, 4)
    yellow = (centre[:, 0] > 170) & (centre[:, 1] > 140) & (centre[:, 2] < 130)
    return float(ring.mean()) < 165.0 and int(yellow.sum()) >= 4


# ---------------------------------------------------------------------------------------------- the command line
def cli_json(*argv: str) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(list(argv)) == 0, argv
    return json.loads(out.getvalue())


def cli_grade(ident: str, seed: int, text: str, attempt: int, lang: str = "en") -> dict:
    """What ``tpm-viz exercise grade ID --seed S --answer=TEXT --attempt K --lang L`` prints."""
    argv = ["exercise", "grade", ident, "--seed", str(seed), f"--answer={text}", "--attempt", str(attempt)]
    return cli_json(*argv, "--lang", lang)


COMMON = ["", "   ", "abc", "1,2.5", "1,000,000", "nan", "inf", "-inf", "1e999", "1e308", "9" * 401, "x" * 201]
COMMON += ["１２", "٣٫٥", "1_000", "1__0", "(1; 2)", "-0", "+5", "5 kg", "5 foo", "5 Hz", "5 N/m", "²m", "1 00"]


def _g(x: float) -> str:
    return f"{x:.6g}"


def number_answers(entry: dict, rng: np.random.Generator) -> list[str]:
    """Answers to a number exercise: right, near and far, each mistake, the units and notations people type, and
    text that is not an answer."""
    ref, unit = entry["ref"], entry["unit"]
    tol = entry["atol"] + entry["rtol"] * abs(ref)
    values = [ref, ref + 0.5 * tol, ref - 0.9 * tol, ref + 1.5 * tol, -ref, 0.0, ref * 1.3]
    values += [ref * m["factor"] for m in entry["mistakes"] if m["factor"] is not None]
    values += [m["value"] for m in entry["mistakes"] if m["value"] is not None]
    values += list(rng.uniform(-3 * abs(ref) - 1, 3 * abs(ref) + 1, 6))
    texts = [repr(float(v)) for v in values] + [_g(v) for v in values]
    texts += [_g(ref).replace(".", ","), _g(ref).replace("-", "\u2212"), f"{ref:.4e}", f" {_g(ref)} ", f"{ref:,.1f}"]
    texts += [f"{ref:.3f}".replace(".", ",") + " " + unit, f"{ref:08.2f}", "1 000", "12 345,5", "1\u00a0000"]
    texts += ["1\u2009000,25", "-1 234.5e-1"]
    per_unit = {
        "mm": [
            f"{_g(ref / 10)} cm",
            f"{_g(ref / 1000)} m",
            f"{_g(ref)} mm",
            f"{_g(ref * 1000)} um",
            f"{_g(ref)}mm",
            f"{_g(ref)} MM",
            f"{_g(ref * 1000)} µm",
            f"{_g(ref)} N",
            f"{_g(ref)} s",
        ],
        "N": [f"{_g(ref / 1000)} kN", f"{_g(ref)} N", f"{_g(ref)}n", f"{_g(ref)} mm", f"{_g(ref)} kg"],
        "deg": [f"{_g(math.radians(ref))} rad", f"{_g(ref)}°", f"{_g(ref)} deg", f"{_g(ref)} mm", f"{_g(ref)} Hz"],
    }
    return texts + per_unit.get(unit, []) + COMMON


def pose_answers(entry: dict, shown: dict, zero_tau2_mm: np.ndarray | None, rng: np.random.Generator) -> list[str]:
    """Answers to a pose exercise: the revealed pose written every way the reader takes, the metres slip, a pose of
    the other force, poses out of reach, outside the stroke, in the other mode and near the singularities, random
    poses over the reachable square, and text that is not two numbers."""
    p1, p2 = shown["answer"]
    la = entry["params"]["l_a"] * 1e3
    texts = [f"{p1!r}; {p2!r}", f"({p1:.3f}, {p2:.3f})", f"{p1:.3f} {p2:.3f}", f"[{p1:.2f}; {p2:.2f}]"]
    texts += [
        f"{_g(p1 / 1000)} m, {_g(p2 / 1000)} m",
        f"{p1:.2f}".replace(".", ",") + "; " + f"{p2:.2f}".replace(".", ","),
    ]
    texts += [f"{p1:.2f}".replace(".", ",") + ", " + f"{p2:.2f}".replace(".", ","), f"{_g(p1)} mm {_g(p2)} mm"]
    texts += [f"{p1 / 1000!r}; {p2 / 1000!r}", f"{p1 + 3:.2f}; {p2 - 2:.2f}", f"{_g(p1 / 10)} cm; {_g(p2 / 10)} cm"]
    if zero_tau2_mm is not None:
        texts.append(f"{zero_tau2_mm[0]!r}; {zero_tau2_mm[1]!r}")
    texts += ["500; 500", f"{la * 0.99:.1f}; 0", f"0; {-la * 0.99:.1f}", "-200; -200", "-250; 30", "0; 0", "150; 150"]
    texts += [f"{-la * 0.72:.1f}; {-la * 0.72:.1f}", f"{la * 0.97:.1f}; 10", "nan; 0", "1e308; 0"]
    for x, y in rng.uniform(-la, la, (30, 2)):
        texts.append(f"{x:.2f}; {y:.2f}")
    return [*texts, "1", "1; 2; 3", "a; b", "1;", "(1, 2", "1 2 3", "1 mm; 2 kg", "1,5; 2,5; 3", *COMMON]


def choice_answers(entry: dict) -> list[str]:
    labels = [o["en"] for o in entry["options"]] + [o["ko"] for o in entry["options"] if o["ko"]]
    keys = [o["key"] for o in entry["options"]]
    return [
        "1",
        "2",
        "3",
        "0",
        *keys,
        *(k.upper() for k in keys),
        *labels,
        *(f" {x.upper()} " for x in labels),
        "x",
        "",
    ]


PIECES = [*"0123456789" * 3, *".,;, -+eE()[]_", "\u2212", "\u00a0", "\u2009", "\u3000", "\t", "mm", "m", "cm", "um"]
PIECES += ["µm", "N", "kN", "deg", "°", "rad", "Hz", "rad/s", "s", "m/s", "m/s²", "s2", "inf", "nan", "x", "١", "３"]
PIECES += ["²", "'", '"', "\\", "\x1c", "\ufeff", "é", "kg", "/", "E+3", "e-2"]
"""What random answers are made of: digits, separators, signs, spaces of every kind, units, Unicode digits."""


def random_answers(rng: np.random.Generator, count: int) -> list[str]:
    """``count`` random answers of 1 to 9 pieces (:data:`PIECES`): mostly format errors, some numbers."""
    return ["".join(rng.choice(PIECES, int(rng.integers(1, 10)))) for _ in range(count)]
