"""Design indices of a 2-PPa over a task rectangle, for either arrangement (``docs/design.md``).

A *task* is the rectangle ``[x0, x1] x [y0, y1]`` [m] the platform must cover, in the machine's frame. For one
design (an :class:`~tpm_viz.paper.arrangement.Arrangement` and its :class:`~tpm_viz.core.params.Params`)
:func:`evaluate` gives :class:`Indices`:

- ``feasible``: every pose of the task is reachable, inside the stroke and clear of both singularities by the
  project's :data:`~tpm_viz.paper.status.WARN` thresholds (``min_i |cos θ_i| >= 0.2``, ``|det J_x| >= 0.2``),
  checked on a grid of at most :data:`CHECK_STEP` that contains the edges and the axes, and no leg crosses the
  other rail or the other leg in plan view at any pose (:func:`tpm_viz.design.clearance.collision`);
- ``gci``: the global conditioning index, the area mean of ``1 / cond(J)`` (Gosselin & Angeles 1991);
- ``cond_max``: the worst ``cond(J)`` over the task;
- ``dyn_mean``, ``dyn_max``: the largest singular value of ``J⁻ᵀ M(p)`` [kg] (actuator force per unit platform
  acceleration at rest; its columns are the closed-form ``τ`` for ``ṗ = 0``, ``p̈ = e_k``), area mean and maximum;
- ``peak_force`` [N]: the peak ``|τ_i|`` of the standard pick (:func:`tpm_viz.design.pick.pick_path`, across the
  task's width or, with ``Settings.pick = "y"``, along its height) run by the paper's cubic law in
  :data:`REFERENCE_STROKE` per stroke; ``cycle_time`` [s]: the time-optimal pick cycle (there and back) within
  ``|τ_i| <= force_limit``: twice the forward stroke of :func:`tpm_viz.app.planner.plan_path` (without friction
  the return stroke is the forward one reversed in time, as :func:`~tpm_viz.app.planner.plan_cycle` shows);
- ``moving_mass`` [kg]; ``footprint_x``, ``footprint_y`` [m]: the bounding box of the rails and the leg centre
  lines over the task.

Area means are composite Gauss-Legendre rules (:data:`GAUSS_ORDER` points per panel side), the panels doubled until
two successive means agree to ``rtol`` (1e-3; the finer one is returned). An infeasible design has NaN indices
(written as empty CSV cells) and ``why`` says what failed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from tpm_viz.app.planner import DEFAULT_GRID, Limits, plan_path
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.design.clearance import collision, joints
from tpm_viz.design.pick import PICK_CORNER, PICK_RISE, peak_cubic, pick_path
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement
from tpm_viz.paper.status import STATUS_WORDS, WARN, PoseStatus, SingularityThresholds

__all__ = [
    "CHECK_STEP",
    "DEFAULT_FORCE_LIMIT",
    "GAUSS_ORDER",
    "INDEX_COLUMNS",
    "PICK_CORNER",
    "PICK_RISE",
    "REFERENCE_STROKE",
    "Indices",
    "Settings",
    "Task",
    "area_means",
    "evaluate",
    "footprint",
    "pick_path",
    "pointwise",
    "reason",
    "task_axes",
    "task_grid",
]

INDEX_COLUMNS = (
    "feasible",
    "gci",
    "cond_max",
    "dyn_mean",
    "dyn_max",
    "peak_force",
    "cycle_time",
    "moving_mass",
    "footprint_x",
    "footprint_y",
)
"""The index columns of a design row, in order (SI units)."""
CHECK_STEP = 2.5e-3
"""Largest spacing [m] of the grid on which feasibility, worst values and the footprint are found."""
MAX_CHECK_SIDE = 81
"""At most this many grid points per side (a task over 0.2 m is checked more coarsely)."""
GAUSS_ORDER = 8
"""Gauss-Legendre points per panel side."""
MAX_PANELS = 32
"""Most panels per side before an area mean is declared unconverged."""
REFERENCE_STROKE = 0.2
"""Duration [s] of one stroke of the standard pick for ``peak_force`` (the paper's Fig. 4 line takes 0.2 s)."""
DEFAULT_FORCE_LIMIT = 100.0
"""Default actuator force limit [N] of the cycle time."""
MAX_TASK = 10.0
"""Largest task side [m]."""


@dataclass(frozen=True)
class Task:
    """The rectangle ``[x0, x1] x [y0, y1]`` [m] the platform must cover (machine frame)."""

    x0: float
    x1: float
    y0: float
    y1: float

    def __post_init__(self) -> None:
        values = [float(v) for v in (self.x0, self.x1, self.y0, self.y1)]
        if not all(math.isfinite(v) and abs(v) <= MAX_TASK for v in values):
            raise InputError("the task X0,X1,Y0,Y1 must be finite numbers of metres within ±10 m")
        if not (values[0] < values[1] and values[2] < values[3]):
            raise InputError("the task X0,X1,Y0,Y1 needs X0 < X1 and Y0 < Y1 (metres)")
        for name, value in zip(("x0", "x1", "y0", "y1"), values, strict=True):
            object.__setattr__(self, name, value)

    @classmethod
    def parse(cls, text: str) -> Task:
        """``"X0,X1,Y0,Y1"`` in metres."""
        parts = [p.strip() for p in str(text).split(",")]
        try:
            x0, x1, y0, y1 = (float(p) for p in parts)
        except ValueError:
            raise InputError(
                "the task must be four numbers X0,X1,Y0,Y1 in metres (e.g. --task=-0.1,0.1,-0.05,0.05)"
            ) from None
        return cls(x0, x1, y0, y1)

    @property
    def width(self) -> float:
        return self.x1 - self.x0

    @property
    def height(self) -> float:
        return self.y1 - self.y0

    @property
    def centre(self) -> np.ndarray:
        return np.array([(self.x0 + self.x1) / 2, (self.y0 + self.y1) / 2])

    def centred_at(self, x: float, y: float) -> Task:
        """The same rectangle moved so that its centre is ``(x, y)`` [m]."""
        return Task(x - self.width / 2, x + self.width / 2, y - self.height / 2, y + self.height / 2)

    def text(self) -> str:
        """``X0,X1,Y0,Y1`` [m] as typed on the command line."""
        return ",".join(f"{v:.6g}" for v in (self.x0, self.x1, self.y0, self.y1))


@dataclass(frozen=True)
class Settings:
    """How the indices are computed: force limit [N], thresholds, area-mean tolerance, planner grid points, and the
    direction of the standard pick (``"x"``: across the task's width; ``"y"``: along its height)."""

    force_limit: float = DEFAULT_FORCE_LIMIT
    thresholds: SingularityThresholds = WARN
    rtol: float = 1e-3
    planner_grid: int = DEFAULT_GRID
    pick: str = "x"

    def __post_init__(self) -> None:
        if self.pick not in ("x", "y"):
            raise InputError(f"the pick runs along x or y, got {str(self.pick)[:20]!r}")


@dataclass(frozen=True)
class Indices:
    """The indices of one design over one task (NaN when infeasible; ``why`` then says why)."""

    feasible: bool
    gci: float = math.nan
    cond_max: float = math.nan
    dyn_mean: float = math.nan
    dyn_max: float = math.nan
    peak_force: float = math.nan
    cycle_time: float = math.nan
    moving_mass: float = math.nan
    footprint_x: float = math.nan
    footprint_y: float = math.nan
    why: str | Phrase = field(default="", compare=False)
    """Why it is infeasible: a phrase shown in each tab's language (``str()``: English, as the CSV writes it)."""
    shortfall: float = field(default=0.0, compare=False)
    """How far an infeasible design is from feasible, for an optimiser: 1 for parameters with no pose in the
    stroke, the fraction of the check grid not regular for a task not covered, 0 otherwise."""

    def row(self) -> dict[str, float]:
        """``{column: value}`` in :data:`INDEX_COLUMNS` order (``feasible`` as 1.0 or 0.0)."""
        return {name: float(getattr(self, name)) for name in INDEX_COLUMNS}


def _linspace_with(lo: float, hi: float, n: int) -> np.ndarray:
    """``n`` even points from ``lo`` to ``hi`` and 0 when it lies inside (where ``d_i`` is extreme along ``p_j``)."""
    xs = np.linspace(lo, hi, n)
    return np.unique(np.append(xs, 0.0)) if lo < 0.0 < hi else xs


def task_axes(task: Task, step: float = CHECK_STEP) -> tuple[np.ndarray, np.ndarray]:
    """The check grid's sorted X and Y values [m]: at most ``step`` apart (fewer for a large task), edges and axes
    included."""
    nx = min(max(math.ceil(task.width / step) + 1, 9), MAX_CHECK_SIDE)
    ny = min(max(math.ceil(task.height / step) + 1, 9), MAX_CHECK_SIDE)
    return _linspace_with(task.x0, task.x1, nx), _linspace_with(task.y0, task.y1, ny)


def task_grid(task: Task, step: float = CHECK_STEP) -> np.ndarray:
    """Points ``(n, 2)`` [m] of :func:`task_axes`' grid."""
    xs, ys = task_axes(task, step)
    return np.stack(np.meshgrid(xs, ys, indexing="ij"), -1).reshape(-1, 2)


def _svd2(m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Singular values ``(σ_max, σ_min)`` of 2 x 2 matrices ``(..., 2, 2)`` in closed form."""
    s = np.sum(m**2, axis=(-2, -1))
    det = np.abs(m[..., 0, 0] * m[..., 1, 1] - m[..., 0, 1] * m[..., 1, 0])
    big = np.sqrt(0.5 * (s + np.sqrt(np.maximum(s**2 - 4 * det**2, 0.0))))
    return big, det / big


def _inverse_condition(arrangement: Arrangement, params: Params, p: np.ndarray) -> np.ndarray:
    """``1 / cond(J)`` per pose ``(n,)``."""
    big, small = _svd2(arr.jacobians(arrangement, params, p).j)
    return small / big


def _dynamic(arrangement: Arrangement, params: Params, p: np.ndarray) -> np.ndarray:
    """``σ_max(J⁻ᵀ M(p))`` [kg] per pose ``(n,)``."""
    return _svd2(arr.force_per_acceleration(arrangement, params, p))[0]


def pointwise(arrangement: Arrangement, params: Params, p: np.ndarray) -> np.ndarray:
    """``(1 / cond(J), σ_max(J⁻ᵀ M))`` per pose, shape ``(n, 2)`` (poses must be regular)."""
    return np.stack([_inverse_condition(arrangement, params, p), _dynamic(arrangement, params, p)], -1)


def _gauss_rule(task: Task, panels: int, order: int = GAUSS_ORDER) -> tuple[np.ndarray, np.ndarray]:
    """Nodes ``(n, 2)`` and weights ``(n,)`` (summing to 1) of the composite rule on ``panels²`` panels."""
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(0.0, 1.0, panels + 1)
    u = ((edges[:-1, None] + edges[1:, None]) / 2 + (x[None, :] / 2) / panels).ravel()
    wu = np.tile(w / 2 / panels, panels)
    px, py = task.x0 + task.width * u, task.y0 + task.height * u
    nodes = np.stack(np.meshgrid(px, py, indexing="ij"), -1).reshape(-1, 2)
    return nodes, np.outer(wu, wu).ravel()


def area_means(f: Callable[[np.ndarray], np.ndarray], task: Task, rtol: float = 1e-3) -> tuple[np.ndarray, int]:
    """Area means over ``task`` of the columns of ``f(points) -> (n, k)``, and the panels per side used.

    Composite Gauss-Legendre (:data:`GAUSS_ORDER` × :data:`GAUSS_ORDER` nodes per panel), panels per side 1, 2, 4,
    ... until every column's mean changes by at most ``rtol`` of its value from one doubling to the next.
    """
    nodes, weights = _gauss_rule(task, 1)
    previous = weights @ f(nodes)
    panels = 1
    while panels < MAX_PANELS:
        panels *= 2
        nodes, weights = _gauss_rule(task, panels)
        current = weights @ f(nodes)
        if np.all(np.abs(current - previous) <= rtol * np.abs(current) + 1e-300):
            return current, panels
        previous = current
    raise InputError(f"the area means did not converge to {rtol:g} with {panels} panels")


def _refined_max(
    g: Callable[[np.ndarray], np.ndarray], task: Task, grid: np.ndarray, values: np.ndarray, levels: int = 2
) -> float:
    """The maximum of ``g(points) -> (n,)`` over the task: the grid's best point, then two zooms of a 21 x 21 grid
    over the neighbouring cells (each 10 times finer)."""
    best = int(np.argmax(values))
    centre, top = grid[best], float(values[best])
    hx = task.width / (len(np.unique(grid[:, 0])) - 1)
    hy = task.height / (len(np.unique(grid[:, 1])) - 1)
    for _ in range(levels):
        xs = np.clip(centre[0] + np.linspace(-hx, hx, 21), task.x0, task.x1)
        ys = np.clip(centre[1] + np.linspace(-hy, hy, 21), task.y0, task.y1)
        pts = np.stack(np.meshgrid(xs, ys, indexing="ij"), -1).reshape(-1, 2)
        vals = g(pts)
        k = int(np.argmax(vals))
        if vals[k] > top:
            centre, top = pts[k], float(vals[k])
        hx, hy = hx / 10, hy / 10
    return top


def footprint(arrangement: Arrangement, params: Params, grid: np.ndarray) -> tuple[float, float]:
    """Width and depth [m] of the bounding box of both rails (``A_i`` from ``d_i = 0`` to ``Δd``) and the leg
    centre lines ``A_i B_i`` over the poses ``grid``."""
    ends = np.array([[0.0, 0.0], [params.stroke, params.stroke]])
    rails, _ = joints(arrangement, params, np.zeros((2, 2)), ends)
    a_pts, b_pts = joints(arrangement, params, grid, arr.inverse_kinematics(arrangement, params, grid))
    pts = np.concatenate([rails.reshape(-1, 2), a_pts.reshape(-1, 2), b_pts.reshape(-1, 2)])
    size = pts.max(axis=0) - pts.min(axis=0)
    return float(size[0]), float(size[1])


_NOT_COVERED = "the task is not covered: ({x:.1f}, {y:.1f}) mm is {status}"
_NO_CYCLE = "no pick cycle within the force limit: {why}"


def reason(why: object) -> str | Phrase:
    """``why`` as an infeasible design's reason: a phrase as it is, an error by its phrase (or its text)."""
    if isinstance(why, BaseException):
        why = why.args[0] if why.args and isinstance(why.args[0], Phrase) else str(why)
    return why if isinstance(why, Phrase) else str(why)


def _infeasible(why: object, shortfall: float = 0.0) -> Indices:
    return Indices(False, why=reason(why), shortfall=shortfall)


def evaluate(
    arrangement: Arrangement, params: Params, task: Task, settings: Settings = Settings(), cycle_only: bool = False
) -> Indices:
    """Every index of one design over ``task`` (see the module docstring); ``cycle_only``: feasibility, cycle
    time, moving mass and footprint only, the other indices NaN (an optimiser's objective, half the work)."""
    arrangement = Arrangement.parse(arrangement)
    try:
        arr.validate(arrangement, params)
    except TpmVizError as exc:
        return _infeasible(exc, 1.0)
    xs, ys = task_axes(task)
    grid = task_grid(task)
    status = arr.classify(arrangement, params, grid, settings.thresholds)
    bad = np.flatnonzero(status != PoseStatus.REGULAR)
    if bad.size:
        k = int(bad[np.argmax(status[bad])])
        status_k = STATUS_WORDS[PoseStatus(int(status[k]))]
        where = Phrase(_NOT_COVERED, x=grid[k, 0] * 1e3, y=grid[k, 1] * 1e3, status=status_k)
        return _infeasible(where, bad.size / len(grid))
    crossing = collision(arrangement, params, xs, ys)
    if crossing is not None:
        return _infeasible(crossing)
    path = pick_path(task, settings.pick)
    try:
        plan = plan_path(params, path, Limits(settings.force_limit), settings.planner_grid, arrangement)
    except TpmVizError as exc:
        return _infeasible(Phrase(_NO_CYCLE, why=reason(exc)))
    width, depth = footprint(arrangement, params, grid)
    cycle = Indices(
        True, cycle_time=2.0 * plan.duration, moving_mass=params.moving_mass, footprint_x=width, footprint_y=depth
    )
    if cycle_only:
        return cycle
    (gci, dyn_mean), _ = area_means(lambda p: pointwise(arrangement, params, p), task, settings.rtol)
    values = pointwise(arrangement, params, grid)
    cond_max = -1.0 / _refined_max(lambda p: -_inverse_condition(arrangement, params, p), task, grid, -values[:, 0])
    dyn_max = _refined_max(lambda p: _dynamic(arrangement, params, p), task, grid, values[:, 1])
    return replace(
        cycle,
        gci=float(gci),
        cond_max=float(cond_max),
        dyn_mean=float(dyn_mean),
        dyn_max=float(dyn_max),
        peak_force=peak_cubic(arrangement, params, path, REFERENCE_STROKE),
    )
