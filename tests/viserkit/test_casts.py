"""The ``casts`` patch (``tpm_viz/viserkit/casts.py``) does what viser 1.1.1's own two checks do, for every input:
compared with viser's functions themselves and with ``np.allclose``. Its need: ``test_patches.py::test_casts``."""

from __future__ import annotations

import math
import typing

import numpy as np
import viser
from hypothesis import given
from hypothesis import strategies as st

from tpm_viz.viserkit import casts
from tpm_viz.viserkit.probe import messages

_SPECIAL = [0.0, -0.0, 1.0, 1.0 + 1e-9, 1.0 + 2e-5, -1.0, 1e-9, -1e-9, 1e300, math.inf, -math.inf, math.nan]
_NUMBERS = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from(_SPECIAL))


def test_close_is_numpys_allclose_for_every_pair_of_special_numbers():
    for a in _SPECIAL:
        for b in _SPECIAL:
            for new, current in (((a, a, a), [b, b, b]), ((a, 1.0, 2.0), [b, 1.0, 2.0]), ((0.0, a), [0.0, b])):
                assert casts.close(new, current) == bool(np.allclose(new, current)), (new, current)


@given(st.integers(3, 4).flatmap(lambda n: st.tuples(st.lists(_NUMBERS, min_size=n, max_size=n), st.just(n))))
def test_close_is_numpys_allclose(pair):
    values, n = pair
    new, current = tuple(values[: n // 2] + values[n // 2 :]), list(reversed(values))
    assert casts.close(new, current) == bool(np.allclose(new, current))
    assert casts.close(new, list(new)) == bool(np.allclose(new, new))


def _run(setter, current: np.ndarray, value) -> tuple[object, list, list]:
    """What a pose setter does with ``value``: the error it raises (or None), ``current`` after, the messages queued."""
    queued: list = []
    try:
        setter(current, value, len(current), queued.append, lambda v: ("message", v))
    except ValueError as exc:
        return type(exc), current.tolist(), queued
    return None, current.tolist(), queued


@given(
    st.sampled_from([3, 4]),
    st.lists(_NUMBERS, min_size=2, max_size=5),
    st.lists(st.floats(-10, 10), min_size=4, max_size=4),
    st.booleans(),
)
def test_the_pose_setter_is_vipers(length, value, start, as_array):
    """Same error, same array afterwards, same messages, for values near, equal to and far from the current one,
    of the right and the wrong length, as a tuple or an array."""
    value = np.array(value) if as_array else tuple(value)
    ours = _run(casts.set_pose_vector, np.array(start[:length]), value)
    theirs = _run(casts.VISER["pose"], np.array(start[:length]), value)
    assert repr(ours) == repr(theirs)  # NaN compared as text
    near = tuple(x * (1 + 1e-7) for x in start[:length])
    assert repr(_run(casts.set_pose_vector, np.array(start[:length]), near)) == repr(
        _run(casts.VISER["pose"], np.array(start[:length]), near)
    )


class _Viser:
    """What viser's own cast needs of ``self``: its recursion."""

    _cast_value_recursive = casts.VISER["cast"]


_HINTS = sorted(
    {
        (name, hint)
        for cls in vars(messages).values()
        if isinstance(cls, type) and cls.__name__.endswith("Props")
        for name, hint in typing.get_type_hints(cls).items()
    },
    key=repr,
)
_VALUES = [
    None,
    1.5,
    3,
    True,
    "text",
    ("a", "b"),
    ("a", None),
    (1.0, 2.0, 3.0),
    (1, 2, 3),
    ((1.0, 2.0), (3.0, 4.0)),
    np.arange(6, dtype=np.float64).reshape(2, 3),
    np.arange(3, dtype=np.int64),
    (np.arange(3, dtype=np.float32), np.arange(2, dtype=np.float32)),
    [(255, 0, 0), (0, 0, 255)],
    (0.5, 0.25, 1.0),
]


def _same(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return type(a) is type(b) and a.dtype == b.dtype and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return type(a) is type(b) and a == b


def _outcome(cast, *args):
    try:
        return cast(*args)
    except Exception as exc:  # the kind of failure is what is compared
        return type(exc)


def test_the_cast_is_visers_for_every_property_of_every_handle():
    """Every property hint of viser's messages, with values of every shape a handle is given."""
    assert len(_HINTS) > 100
    for name, hint in _HINTS:
        for value in _VALUES:
            ours = _outcome(casts.cast_value, hint, value, name)
            theirs = _outcome(casts.VISER["cast"], _Viser(), hint, value, name)
            assert _same(ours, theirs), (name, hint, value, ours, theirs)


def test_the_version_has_every_internal_the_patch_uses():
    assert casts.missing() == []
    assert viser.__version__.startswith("1.1.")


def test_a_plain_viser_server_beside_a_tpm_viz_server_keeps_visers_own_checks(serve, monkeypatch):
    """The patch is guarded: a node of a plain server still asks ``np.allclose``; one of tpm-viz's server does not."""
    ours, _ = serve()
    plain = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    calls: list[int] = []
    allclose = np.allclose
    monkeypatch.setattr(np, "allclose", lambda *a, **k: (calls.append(1), allclose(*a, **k))[1])
    try:
        ours.scene.add_frame("/probe", show_axes=False, position=(0.1, 0.0, 0.0))
        assert calls == []
        plain.scene.add_frame("/probe", show_axes=False, position=(0.1, 0.0, 0.0))
        assert len(calls) >= 2
    finally:
        plain.stop()
