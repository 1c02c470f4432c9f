"""screwkin: screw-theory analysis of serial and parallel mechanisms described in URDF.

>>> import screwkin
>>> mech = screwkin.load("robots/fourbar_crank_rocker.urdf")
>>> mech.mobility().mobility
1
"""

from .errors import AssemblyError, MechanismFileError, ScrewkinError, UsageError
from .mechanism import Mechanism, load
from .mobility import MobilityResult, OutputMotion
from .tolerances import Tolerances
from .topology import Joint, Topology

__all__ = [
    "load",
    "Mechanism",
    "MobilityResult",
    "OutputMotion",
    "Topology",
    "Joint",
    "Tolerances",
    "ScrewkinError",
    "UsageError",
    "MechanismFileError",
    "AssemblyError",
]
__version__ = "0.1.0"
