"""The report's sections, one module per section id.

Each section is a function ``f(ctx)`` of a :class:`~labbrdf.report.context.Context` that adds
text, tables, figures and checks to ``ctx.b`` (a :class:`~labbrdf.report.builder.Builder`).
A section whose inputs or modules are missing raises
:class:`~labbrdf.report.builder.Unavailable` (rendered "not available: <reason>", its checks
skipped). The workflows :mod:`labbrdf.report.validate` and :mod:`labbrdf.report.user` list
the sections they run as ``(id, title, function)``; :func:`run` runs such a list.

=========================  ====================================================================
module                     section id(s)
=========================  ====================================================================
:mod:`.ingest`             ``ingest``
:mod:`.measured`           ``measured``
:mod:`.nk`                 ``nk``
:mod:`.film`               ``film`` (user: a stack fitted to angle-dependent psi/Delta)
:mod:`.fits`               ``fits``
:mod:`.scans`              ``scans``
:mod:`.spectra`            ``spectra``
:mod:`.hemispherical`      ``hemispherical``
:mod:`.physics`            ``physics``
:mod:`.compare`            ``compare``
:mod:`.colour`             ``colour``
:mod:`.tracer`             ``tracer_maps``, ``tracer_validation``
:mod:`.errata`             ``errata``
:mod:`.surface`            ``surface`` (user: height maps; validation: Gaussian ACF)
:mod:`.psd`                ``psd`` (user: PSD of each sample's height maps, composite, fit)
:mod:`.smoothness`         ``smoothness`` (user: a height map against one sample's reflectance)
:mod:`.prediction`         ``prediction`` (user: tracer prediction beside a measured BRDF)
:mod:`.model_measurement`  ``model_measurement`` (validation: the two above on a bundled set)
:mod:`.scatter`            ``scatter`` (user: ABg beside physical models, files for the designer)
=========================  ====================================================================
"""

from __future__ import annotations

from collections.abc import Callable, Container, Sequence
from typing import TypeAlias

from ..context import Context

__all__ = ["Section", "run"]

#: one section of a workflow: id (the module's name), title, function of the Context
Section: TypeAlias = tuple[str, str, Callable[[Context], object]]


def run(ctx: Context, sections: Sequence[Section], only: Container[str] | None = None) -> None:
    """Run ``sections`` in order, each in its own ``ctx.b.section`` (``only``: a subset)."""
    for sid, title, fn in sections:
        if only is not None and sid not in only:
            continue
        with ctx.b.section(sid, title):
            fn(ctx)
