"""Survey the mobility of every closed-loop leg in the example-parallel-robots corpus.

Run:  python examples/corpus_survey.py [FOLDER]
FOLDER defaults to robots/corpus/example-parallel-robots (bundled with screwkin).

For each robot it prints the Kutzbach count, the screw-theory mobility (rank of
the loop-closure constraint Jacobian), the idle DOFs and how the motors relate
to the effective mobility -- or why the loops cannot be closed.
"""

import sys
from pathlib import Path

import screwkin
from screwkin.present.tables import table

default = Path(__file__).resolve().parents[1] / "robots" / "corpus" / "example-parallel-robots"
folder = Path(sys.argv[1]) if len(sys.argv) > 1 else default

urdfs = sorted(folder.glob("*/robot.urdf"))
if not urdfs:
    sys.exit(f"no */robot.urdf in {folder}")
rows = []
for urdf in urdfs:
    mech = screwkin.load(urdf, warn=lambda message: None)  # their meshes are not shipped
    try:
        r = mech.mobility()
    except screwkin.AssemblyError as exc:
        rows.append((urdf.parent.name, "-", "-", "-", "-", len(mech.actuated), f"not assembled (residual {exc.residual:.3g})"))
        continue
    rows.append((urdf.parent.name, r.kutzbach, r.mobility, r.idle_dofs, r.effective_mobility,
                 len(r.actuated), r.classification))

print(table(["robot", "Kutzbach", "M", "idle", "effective", "motors", "classification"], rows))
