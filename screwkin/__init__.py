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

from .analysis.singularities.batch import SerialJacobians
from .analysis.forces.dynamics import DynamicsResult, Load, dynamics
from .analysis.motion.ik import inverse_kinematics
from .analysis.mobility import (
    IdleMotion,
    MobilityResult,
    OutputMotion,
    analyze_mobility,
)
from .analysis.motion.position import PositionResult, PositionSolver, Solution
from .analysis.singularities.scan import ScanResult, scan
from .analysis.singularities.singular import SingularityReport, classify
from .analysis.design.study import StudyResult, pareto_front
from .parallel.study import run_study as _run_study
from .analysis.motion.singular_points import locate_singularities
from .analysis.motion.sweep import SweepResult, SweepSingularity, sweep
from .errors import AssemblyError, MechanismFileError, ScrewkinError, UsageError
from .model import loader as _loader
from .model import mechanism as _mechanism
from .model.topology import Joint, Topology
from .present.report import to_dict
from .tolerances import Tolerances

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

    def mobility(self, actuated=None, output=None, seed: int = 0, point: bool = False) -> MobilityResult:
        """Mobility analysis (screwkin.analysis.mobility.analyze_mobility); actuated: actuated
        joint names overriding the file's; point: the output link's origin as a point."""
        if actuated is not None:
            self.set_actuated(actuated)
        return analyze_mobility(self, output=output, seed=seed, point=point)


def load(path, yaml=None, actuated=None, tolerances: Tolerances = _loader.DEFAULT, warn=None,
         package_dirs=None, args=None) -> Mechanism:
    """Read a mechanism file (URDF with <loop_joint> or a YAML sidecar, SDF, or a xacro file
    with its arguments ``args``, e.g. ``{"crank": "30mm"}``) into a :class:`Mechanism`; see
    screwkin.model.loader.load for the arguments."""
    return _loader.load(path, yaml=yaml, actuated=actuated, tolerances=tolerances, warn=warn,
                        package_dirs=package_dirs, cls=Mechanism, args=args)


def study(spec, scheduler=None, workers=None, progress=None, timeout: float = 10.0, base=None) -> StudyResult:
    """Run a design-space study (what ``screwkin study`` runs): ``spec`` a spec file's path or
    a dict as the YAML (its ``file`` relative to ``base``); on a LocalCluster of ``workers``
    processes, or on the dask.distributed cluster at ``scheduler`` (``tcp://host:port``);
    ``workers=0`` in this process.  Returns a StudyResult: ``.rows`` (dicts, SI), ``.table``
    (columns); screwkin.present.study writes CSV, Parquet, text and plots."""
    return _run_study(spec, scheduler=scheduler, workers=workers, progress=progress, timeout=timeout, base=base)
