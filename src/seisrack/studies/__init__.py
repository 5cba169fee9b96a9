"""Studies: record suites, intensity stripes or IDA, sampled friction and occupancy, at scale.

Public API:

- :func:`load_study` -> :class:`StudySpec` (``spec``): the study TOML, validated at the boundary
  (every key in ``docs/user/study_toml.md``);
- :func:`expand` -> list of :class:`Run` with stable ids; :func:`plan` -> :class:`StudyPlan`
  (runs plus the racks and records the workers need) (``expand``);
- :func:`run_study` -> :class:`StudyRunSummary`: execute on a local process pool or a Dask
  cluster, append rows to the Parquet store, resume what is missing (``run``, ``executors``);
- :func:`read_runs` -> ``pyarrow.Table``, one row per run id, sorted (``store``).
"""

from seisrack.studies.expand import Run, StudyPlan, expand, plan
from seisrack.studies.run import StudyRunSummary, run_study
from seisrack.studies.spec import StudySpec, load_study
from seisrack.studies.store import COLUMNS, read_runs

__all__ = ["COLUMNS", "Run", "StudyPlan", "StudyRunSummary", "StudySpec", "expand",
           "load_study", "plan", "read_runs", "run_study"]
