"""screwkin: screw-theory analysis of serial and parallel mechanisms described in URDF.

>>> import screwkin
>>> mech = screwkin.load("robots/fourbar_crank_rocker.urdf")
>>> mech.mobility().mobility
1

The package is laid out by layer, imports running one way (README, "How the code is
laid out"): ``files`` (text -> description) <- ``model`` (the Pinocchio model, loops,
topology) <- ``analysis`` (results) <- ``present`` (text, JSON, pictures, views) <-
``cli``.  This module is the public API on top of them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from .errors import AssemblyError, MechanismFileError, ScrewkinError, UsageError
from .model import loader as _loader
from .model import mechanism as _mechanism
from .tolerances import Tolerances

if TYPE_CHECKING:  # the return types of the methods below, imported lazily at run time
    from .analysis.design.study import StudyResult
    from .analysis.mobility import MobilityResult
    from collections.abc import Callable
    from pathlib import Path
    from screwkin.present.progress import Progress
    from collections.abc import Sequence
    from screwkin.files.study import StudySpec

#: The rest of the public API, imported when first used (``screwkin.sweep``, ``from screwkin import
#: scan``): ``import screwkin`` (and the command line, which imports it) loads the model layer
#: only, not every analysis.
_LAZY = {
    "SerialJacobians": ".analysis.singularities.batch",
    "DynamicsResult": ".analysis.forces.dynamics", "Load": ".analysis.forces.dynamics",
    "dynamics": ".analysis.forces.dynamics",
    "inverse_kinematics": ".analysis.position.ik",
    "IdleMotion": ".analysis.mobility", "MobilityResult": ".analysis.mobility", "OutputMotion": ".analysis.mobility",
    "analyze_mobility": ".analysis.mobility",
    "PositionResult": ".analysis.position.position", "PositionSolver": ".analysis.position.position",
    "Solution": ".analysis.position.position",
    "ScanResult": ".analysis.singularities.scan", "scan": ".analysis.singularities.scan",
    "SingularityReport": ".analysis.singular", "classify": ".analysis.singular",
    "StudyResult": ".analysis.design.study", "pareto_front": ".analysis.design.study",
    "locate_singularities": ".analysis.motion.singular_points",
    "SweepResult": ".analysis.motion.sweep", "SweepSingularity": ".analysis.motion.sweep",
    "sweep": ".analysis.motion.sweep",
    "Joint": ".model.topology", "Topology": ".model.topology",
    "to_dict": ".present.report",
    "run_study": ".parallel.study",  # (screwkin.study below)
}


def __getattr__(name: str) -> Callable:
    """The public name ``name`` from its module, imported now (PEP 562)."""
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_LAZY[name], __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list:
    return sorted(set(globals()) | set(_LAZY))


__all__ = [
    "load",
    "Mechanism",
    "MobilityResult",
    "OutputMotion",
    "IdleMotion",
    "Topology",
    "Joint",
    "PositionSolver",
    "PositionResult",
    "Solution",
    "inverse_kinematics",
    "SingularityReport",
    "classify",
    "SweepResult",
    "SweepSingularity",
    "sweep",
    "locate_singularities",
    "dynamics",
    "DynamicsResult",
    "Load",
    "ScanResult",
    "scan",
    "study",
    "StudyResult",
    "pareto_front",
    "SerialJacobians",
    "to_dict",
    "Tolerances",
    "ScrewkinError",
    "UsageError",
    "MechanismFileError",
    "AssemblyError",
]
__version__ = "0.1.0"


class Mechanism(_mechanism.Mechanism):
    """A mechanism (screwkin.model.mechanism.Mechanism) with the analysis asked most often
    as a method: ``mech.mobility()``."""

    def mobility(self, actuated: list[str] | None=None, output: str | None=None, seed: int = 0, point: bool = False) -> MobilityResult:
        """Mobility analysis (screwkin.analysis.mobility.analyze_mobility); actuated: actuated
        joint names overriding the file's; point: the output link's origin as a point."""
        if actuated is not None:
            self.set_actuated(actuated)
        return __getattr__("analyze_mobility")(self, output=output, seed=seed, point=point)


def load(path: str | Path, yaml=None, actuated: list | None=None, tolerances: Tolerances = _loader.DEFAULT, warn: Callable | None=None,
         package_dirs: Sequence[str] | None=None, args: dict | None=None):
    """Read a mechanism file (URDF with <loop_joint> or a YAML sidecar, SDF, or a xacro file
    with its arguments ``args``, e.g. ``{"crank": "30mm"}``) into a :class:`Mechanism`; see
    screwkin.model.loader.load for the arguments."""
    return _loader.load(path, yaml=yaml, actuated=actuated, tolerances=tolerances, warn=warn,
                        package_dirs=package_dirs, cls=Mechanism, args=args)


def study(spec: StudySpec | dict, scheduler: str | None=None, workers: int | None=None, progress: Progress | None=None, timeout: float = 10.0, base: str | Path | None=None) -> StudyResult:
    """Run a design-space study (what ``screwkin study`` runs): ``spec`` a spec file's path or
    a dict as the YAML (its ``file`` relative to ``base``); on a LocalCluster of ``workers``
    processes, or on the dask.distributed cluster at ``scheduler`` (``tcp://host:port``);
    ``workers=0`` in this process.  Returns a StudyResult: ``.rows`` (dicts, SI), ``.table``
    (columns); screwkin.present.study writes CSV, Parquet, text and plots."""
    return __getattr__("run_study")(spec, scheduler=scheduler, workers=workers, progress=progress, timeout=timeout,
                                    base=base)
