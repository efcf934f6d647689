"""The style sheets of the panel: viser's number box beside a slider hidden (:func:`slider_css`), and the readout
folded to its compact form (:data:`FOLDED`) while another tab is open (:func:`fold_css`). Each is markup made here
from viser's uuids (:class:`~tpm_viz.core.markup.Html`)."""

from __future__ import annotations

from tpm_viz.core.markup import Html
from tpm_viz.viserkit.core import tab_id, widget_uuid

__all__ = ["FOLDED", "fold_css", "slider_css"]


def slider_css(handles) -> Html:
    """A style rule that hides viser's number box beside each of these sliders (the slider itself stays): in viser
    1.1.1 the box is the sibling after the slider's root, whose ``id`` is the handle's uuid."""
    try:
        uuids = [widget_uuid(h) for h in handles]
    except AttributeError:  # a GUI without a page (the tests' stand-in for viser): nothing to hide
        return Html("")
    rules = ", ".join(f'[id="{uuid}"] ~ *' for uuid in uuids)
    return Html(f"<style>{rules} {{ display: none !important; }}</style>")


FOLDED = (
    'div:has(> [data-q="banner"]) tr:nth-child(n+3)',  # θ, det J_x, det J_q, cond J, assembly mode
    'div:has(> [data-q="banner"]) > div:last-child > div:first-child',  # the forces' heading and load line
    'div:has(> [data-q="tau1_ref"])',  # Pinocchio's cross-check of each force
    'div:has(> [data-q="tau2_ref"])',
)
"""What the compact readout leaves out: it keeps the pose status and its warnings, p, d, τ₁ and τ₂ with their bars."""


def _tab_selector(tab) -> str:
    """A CSS selector of a tab's button, on a wide screen (viser's dock tab) and on a phone (a Mantine tab)."""
    uuid = tab_id(tab)
    return f':is([data-dock-tab="{uuid}"], [id$="-tab-{uuid}"])' if uuid is not None else ""


def fold_css(explore, shown) -> Html:
    """A style sheet that folds the readout to :data:`FOLDED`'s compact form while the guide is open or any tab but
    ``shown`` (Move, Forces) of the ``explore`` group is open: the first control of every tab stays on screen at 768
    px."""
    group, tabs = _tab_selector(explore), [_tab_selector(tab) for tab in shown]
    if not group or not all(tabs):
        return Html("")
    folded = ", ".join(FOLDED)
    when = (
        f'body:not(:has({group}[aria-selected="true"]))',
        f'body:not(:has(:is({", ".join(tabs)})[aria-selected="true"]))',
        "body:has([data-guide])",
    )
    rules = " ".join(f":is({w}) :is({folded}) {{ display: none; }}" for w in when)
    return Html(f"<style>{rules}</style>")
