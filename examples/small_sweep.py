"""A small sweep from Python: the largest impulse the RSG recovers on the LIPM in four
directions at mid single support, against the true capture bound of the same LIPM.

Takes about a minute. Run: python examples/small_sweep.py [OUT_FOLDER]
"""

import sys
import tempfile
from pathlib import Path

from app.experiments.envelope import build_envelope, format_table
from app.experiments.jobs import JobRun
from app.experiments.sweep import SweepSpec, run_sweep

spec = SweepSpec(model="lipm", controllers=("rsg", "no-step"), directions=4, phases=(0.5,))
out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="rsg-sweep-"))
records = run_sweep(spec, JobRun(out, workers=2, progress=False))  # resumable: jobs.jsonl in out
for record in records:
    print(f"{record['controller']:8s} {record['direction_deg']:5.0f} deg: "
          f"{record['impulse']:6.1f} N s recovered, bound {record['bound']:6.1f} N s")  # fmt: skip
print(format_table(build_envelope(spec, records)))
