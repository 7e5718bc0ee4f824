"""The figures `tsi study` draws, from a tsi.StudyResult: drawn by the CLI's own script
(scripts/plot_study.py, shipped in this package as tsi._plot_study), so the two agree.

    s = tsi.study(spec)
    tsi.plot.convergence(s)                 # a matplotlib Figure
    tsi.plot.figure(s, "convergence.png")   # the study's kind, saved as the CLI saves it
"""
import os

from . import _plot_study


def _check(study, kind):
    if study.kind != kind:
        raise ValueError(f"a {kind} plot needs a {kind} study; this one is {study.kind!r} (tsi.plot.figure picks "
                         "the study's own)")


def _save(fig, kind, path):
    if path is not None:
        name, dpi = _plot_study.FILES[kind]
        path = os.fspath(path)
        fig.savefig(os.path.join(path, name) if os.path.isdir(path) else path, dpi=dpi)
    return fig


def convergence(study, path=None):
    """Error against h, a panel per scheme, a curve per eps (convergence.png)."""
    _check(study, "convergence")
    return _save(_plot_study.convergence_figure(study.rows, study.title), "convergence", path)


def conservation(study, path=None):
    """err_H, err_I, err_m (and the models' own invariants) against t (conservation.png)."""
    _check(study, "conservation")
    runs = {r.id: r.invariants for r in study.runs if r.invariants}
    return _save(_plot_study.conservation_figure(study.rows, study.title, runs), "conservation", path)


def work_precision(study, path=None):
    """Error against wall time and against evaluations (work_precision.png)."""
    _check(study, "work-precision")
    return _save(_plot_study.work_precision_figure(study.rows, study.title), "work-precision", path)


def figure(study, path=None):
    """The figure of the study's kind; `path` a file, or a directory to save it under the
    CLI's file name."""
    return {"convergence": convergence, "conservation": conservation,
            "work-precision": work_precision}[study.kind](study, path)
