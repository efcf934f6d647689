"""The closed form as C99 for a real-time controller: traced from the Python formulas (:mod:`.expr`,
:mod:`.code`, :mod:`.parallel`), with the fixed text around them (:mod:`.text`, :mod:`.blocks`)."""
