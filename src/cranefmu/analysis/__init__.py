"""The crane analyses: what the runs are checked against and what is computed from them, one module each.

:mod:`.reference` (the monolithic scipy solve of a scene, wired from its own SSD and .ssv), :mod:`.modal`
(each scene's listed modes: closed forms, matrix-pencil fit, check against the monolith), :mod:`.converge`
(``cranefmu converge``: errors against the monolith over a ladder of steps), :mod:`.scene_questions` (each
scene's question judged over its natural length), :mod:`.sway_envelope` (the hook and payload sway envelope),
:mod:`.stability` (the derived stability limit of an explicit coupling), :mod:`.fit_boucwen` (``cranefmu
fit-boucwen``: the hysteretic rope fitted to a hoist loop) and :mod:`.seed_figures` (the seeds' printed and
measured figures the pages compare with).  This file imports nothing: the master and the CLI import only the
module they need.

Public: the modules ``__all__`` names.  Internal: :mod:`.converge` (public as ``cranefmu converge``),
:mod:`.scene_questions` and :mod:`.seed_figures` (what the benchmarks and the generated pages read).
"""

__all__ = ["reference", "modal", "sway_envelope", "stability", "fit_boucwen"]
