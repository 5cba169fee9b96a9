"""Post-processing of a study store: counts, EC8 suite means, fragility fits, IDA curves.

Reads ``DIR/runs/*.parquet`` (one row per run, see :mod:`seisrack.studies.store`) and writes
``DIR/summary/summary.json``, ``DIR/summary/fragility.csv`` and the figures ``fragility.png``
(stripes) and ``ida.png`` (IDA). Only runs with status ``"ok"`` enter the statistics; failed
runs are counted with their reasons.

- *EC8 means.* EN 1998-1 §4.3.3.4.3: with 7 or more records the action effect is the mean over
  the records, otherwise the most unfavourable. Per stripe, each peak is first averaged over the
  runs of one record (friction samples, occupancy patterns), then the mean and the maximum over
  the records are reported with ``n_records``; ``ec8`` is the mean if n_records >= 7, else the max.
- *Fragility on stripes.* Binomial maximum likelihood (Baker 2015, Earthquake Spectra 31(1),
  Eq. 11) for each damage state: ``sliding>d`` (``peak_sliding_max_m > d`` for each d),
  ``any_fall``, and ``base_shear>V`` when a capacity V [N] is given. Bands: 5-95 % bootstrap
  percentiles (runs resampled within each stripe).
- *IDA* (``stripe == -1``): one curve per (record, friction, occupancy); the IM of first
  exceedance per curve gives the method-of-moments fit, bootstrap over the curves. A curve
  stopped by the study's stop rule (its levels above are "skipped" runs) counts as exceeding
  every damage state at its first skipped level (the collapse convention of IDA, Vamvatsikos &
  Cornell 2002): a state not reached up to the stop level gets the stop level as capacity
  (the linear crossing towards an infinite response); ``stopped_im`` gives that level.

Theta is in the units of the intensity measure as stored: m/s² for both PGA and Sa.

Only the runs of the study that ``study.json`` describes enter, with its stripe indices: runs
stored in the folder for another definition of the study (an older store, where a changed
study could be run into the same folder) are left out and counted in ``runs_left_out``, with a
warning. Without a run table in ``study.json`` every stored run enters.
"""

from __future__ import annotations

import csv
import json
import logging
import math
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from seisrack.atomic import atomic_write, save_figure, write_text
from seisrack.errors import InputError
from seisrack.studies import fragility as fr
from seisrack.studies.reduction_summary import COLUMNS as REDUCTION_COLUMNS
from seisrack.studies.reduction_summary import format_reduction, reduction_summary

__all__ = ["DEFAULT_D_SLIDE", "read_runs_table", "runs_as_arrays", "summarize"]

log = logging.getLogger(__name__)

DEFAULT_D_SLIDE = (0.05,)  # [m]
PEAKS = ("peak_sliding_max_m", "n_fall", "base_shear_N", "beam_displacement_max_m",
         "drift_ratio_max", "upright_moment_connection_Nm")
_STR = ("run_id", "rack", "record", "im_measure", "status", "error")
#: the columns of a 3D rack's runs (NaN or False for a 2D rack's, or in an older store)
COLUMNS_3D = ("angle_deg", "any_aisle_fall", "n_aisle_fall", "peak_sliding_down_aisle_max_m",
              "peak_sliding_cross_aisle_max_m")
_NUM = ("im_target", "stripe", "mu_static", "mu_dynamic", "occupancy", "any_fall") + PEAKS \
    + tuple(c for c in REDUCTION_COLUMNS if c not in PEAKS) + COLUMNS_3D
CSV_FIELDS = ("name", "theta", "beta", "theta_lo", "theta_hi", "beta_lo", "beta_hi",
              "n_stripes", "n_runs", "rack", "im_measure", "method", "status")


def read_runs_table(out_dir: str | Path):  # noqa: ANN201
    """All stored runs as a ``pyarrow.Table``, one row per ``run_id``, sorted by ``run_id``.

    Uses :func:`seisrack.studies.store.read_runs` when it is available; otherwise reads the
    part files directly (same contract).
    """
    try:
        from seisrack.studies.store import read_runs
    except ImportError:  # the store module is optional for a reader
        read_runs = _read_runs_local
    return read_runs(out_dir)


def _read_runs_local(out_dir: str | Path):  # noqa: ANN202
    import pyarrow as pa
    import pyarrow.parquet as pq

    parts = sorted((Path(out_dir) / "runs").glob("part-*.parquet"))
    if not parts:
        return pa.table({"run_id": pa.array([], pa.string())})
    table = pa.concat_tables([pq.read_table(p) for p in parts], promote_options="default")
    table = table.sort_by("run_id")
    ids = np.asarray(table.column("run_id").to_pylist(), dtype=object)
    keep = np.ones(ids.size, dtype=bool)
    keep[1:] = ids[1:] != ids[:-1]
    return table.filter(pa.array(keep)) if not keep.all() else table


def runs_as_arrays(table) -> dict[str, np.ndarray]:  # noqa: ANN001
    """Columns needed here as numpy arrays: strings as object arrays ('' for null), numbers
    as float64 (NaN for null). Missing columns are filled the same way."""
    n = table.num_rows
    out: dict[str, np.ndarray] = {}
    names = set(table.column_names)
    for c in _STR:
        vals = table.column(c).to_pylist() if c in names else [None] * n
        out[c] = np.array(["" if v is None else str(v) for v in vals], dtype=object)
    import pyarrow as pa

    for c in _NUM:
        if c not in names:
            out[c] = np.full(n, math.nan)
            continue
        # float64 keeps nulls as NaN; bool and int64 columns are cast first
        col = table.column(c).cast(pa.float64())
        out[c] = np.asarray(col.to_numpy(zero_copy_only=False), dtype=float)
    return out


def check_distinct_thresholds(field: str, d_slide) -> None:  # noqa: ANN001
    """Refuse two sliding thresholds that name the same damage state (``sliding>0.05m``: six
    significant digits), whose counts would otherwise be pooled under one name."""
    names = [f"{d:g}" for d in d_slide]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError(field, list(d_slide), "distinct sliding thresholds [m] (six "
                         f"significant digits tell them apart): {', '.join(dup)} m is given "
                         "twice")


def _damage_states(d_slide, shear_capacity) -> list[tuple[str, str, float]]:
    """(name, column, threshold): exceeding means column > threshold."""
    states = [(f"sliding>{d:g}m", "peak_sliding_max_m", float(d)) for d in d_slide]
    states.append(("any_fall", "any_fall", 0.5))
    if shear_capacity is not None:
        states.append((f"base_shear>{shear_capacity:g}N", "base_shear_N", float(shear_capacity)))
    return states


def _damage_states_3d(d_slide) -> list[tuple[str, str, float]]:
    """The states of a 3D rack's runs: a pallet falls into an aisle, and the sliding along
    each direction beyond each threshold."""
    states = [("aisle_fall", "any_aisle_fall", 0.5)]
    for name in ("down_aisle", "cross_aisle"):
        states += [(f"sliding_{name}>{d:g}m", f"peak_sliding_{name}_max_m", float(d))
                   for d in d_slide]
    return states


def _nan(x: float) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def _band_fields(fit, thetas, betas) -> dict[str, Any]:
    good = np.isfinite(thetas) & np.isfinite(betas)
    if good.sum() >= 2:
        t_lo, t_hi = np.percentile(thetas[good], [5, 95])
        b_lo, b_hi = np.percentile(betas[good], [5, 95])
    else:
        t_lo = t_hi = b_lo = b_hi = math.nan
    return {"theta": _nan(fit.theta), "beta": _nan(fit.beta), "theta_lo": _nan(t_lo),
            "theta_hi": _nan(t_hi), "beta_lo": _nan(b_lo), "beta_hi": _nan(b_hi),
            "se_ln_theta": _nan(fit.se_ln_theta), "se_beta": _nan(fit.se_beta),
            "n_stripes": fit.n_stripes, "n_runs": fit.n_runs, "status": fit.status,
            "method": fit.method, "n_boot_ok": int(good.sum())}


def _peaks(r: dict[str, np.ndarray], idx: np.ndarray) -> dict[str, Any]:
    """EC8 statistics of each peak over the records of the rows ``idx``."""
    recs = r["record"][idx]
    names = sorted(set(recs))
    out: dict[str, Any] = {}
    extra = tuple(c for c in ("n_aisle_fall", "peak_sliding_cross_aisle_max_m")
                  if c in r and np.any(np.isfinite(r[c][idx].astype(float))))  # 3D racks
    for c in PEAKS + extra:
        per_rec = np.array([np.nanmean(r[c][idx][recs == nm]) if np.any(
            np.isfinite(r[c][idx][recs == nm])) else math.nan for nm in names])
        per_rec = per_rec[np.isfinite(per_rec)]
        if per_rec.size == 0:
            out[c] = {"mean": None, "max": None, "ec8": None}
            continue
        mean, mx = float(per_rec.mean()), float(per_rec.max())
        out[c] = {"mean": mean, "max": mx, "ec8": mean if per_rec.size >= 7 else mx}
    return out


def _stripes(r, idx, states, n_boot, seed) -> dict[str, Any]:
    ok = idx[r["status"][idx] == "ok"]
    stripe_ids = np.unique(r["stripe"][idx]).astype(int)
    stripes, im, n_ok = [], [], []
    counts = {name: [] for name, _, _ in states}
    for s in stripe_ids:
        rows = idx[r["stripe"][idx] == s]
        rows_ok = rows[r["status"][rows] == "ok"]
        x = float(np.median(r["im_target"][rows]))
        entry = {"stripe": int(s), "im": x, "n_runs": int(rows.size), "n_ok": int(rows_ok.size),
                 "n_failed": int(rows.size - rows_ok.size),
                 "n_records": len(set(r["record"][rows_ok])), "fraction": {},
                 "peaks": _peaks(r, rows_ok)}
        for name, col, thr in states:
            k = int(np.count_nonzero(r[col][rows_ok] > thr))
            counts[name].append(k)
            entry["fraction"][name] = k / rows_ok.size if rows_ok.size else None
        stripes.append(entry)
        im.append(x)
        n_ok.append(rows_ok.size)
    fits = {}
    for i, (name, _, _) in enumerate(states):
        fit = fr.fit_fragility(im, n_ok, counts[name])
        th, be = (fr.bootstrap_fragility(im, n_ok, counts[name], n_boot, seed + i)
                  if fit.ok and n_boot > 0 else (np.full(0, np.nan), np.full(0, np.nan)))
        fits[name] = _band_fields(fit, th, be)
        fits[name]["_boot"] = (th, be)
    return {"stripes": stripes, "fragility": fits, "n_ok": int(ok.size)}


def _ida(r, idx, states, n_boot, seed) -> dict[str, Any]:
    ok = idx[r["status"][idx] == "ok"]
    # an older store has no angle column (NaN): every curve at 0°
    angle = np.nan_to_num(r["angle_deg"], nan=0.0)
    keys = sorted({(r["record"][i], r["mu_static"][i], r["mu_dynamic"][i], r["occupancy"][i],
                    angle[i]) for i in ok})
    curves = []
    for rec, mu_s, mu_d, occ, ang in keys:
        def same(rows: np.ndarray) -> np.ndarray:
            return ((r["record"][rows] == rec) & (r["mu_static"][rows] == mu_s)  # noqa: B023
                    & (r["mu_dynamic"][rows] == mu_d) & (r["occupancy"][rows] == occ)  # noqa: B023
                    & (angle[rows] == ang))  # noqa: B023

        rows = ok[same(ok)]
        rows = rows[np.argsort(r["im_target"][rows], kind="stable")]
        skip = idx[(r["status"][idx] == "skipped") & same(idx)]
        cv = {"record": rec, "mu_static": _nan(mu_s), "occupancy": _nan(occ),
              "angle_deg": float(ang), "im": r["im_target"][rows].tolist(),
              "stopped_im": float(r["im_target"][skip].min()) if skip.size else None}
        for c in PEAKS + ("any_fall",) + COLUMNS_3D:
            cv[c] = [_nan(v) for v in r[c][rows]]
        curves.append(cv)
    fits = {}
    for i, (name, col, thr) in enumerate(states):
        cap = np.array([_capacity(cv, col, thr) for cv in curves]) if curves else np.zeros(0)
        fit = fr.fit_ida_fragility(cap)
        th, be = fr.bootstrap_ida_fragility(cap, n_boot, seed + i)
        fits[name] = _band_fields(fit, th, be)
        fits[name]["capacities"] = [_nan(c) for c in cap]
    return {"curves": curves, "fragility": fits, "n_ok": int(ok.size)}


def _capacity(cv: dict[str, Any], col: str, thr: float) -> float:
    """IM of first exceedance of one IDA curve; a stopped curve exceeds at ``stopped_im``."""
    im, edp = list(cv["im"]), np.array(cv[col], dtype=float)
    if cv.get("stopped_im") is not None:
        im.append(cv["stopped_im"])
        edp = np.append(edp, math.inf)
    return fr.ida_capacity(im, edp, thr)


def summarize(out_dir: str | Path, *, d_slide=DEFAULT_D_SLIDE, shear_capacity: float | None = None,
              n_boot: int = 200, seed: int = 0, write: bool = True, plots: bool = True,
              boots: list | None = None, hazard: str | Path | None = None) -> dict[str, Any]:
    """Summary of the study stored in ``out_dir`` (see the module docstring).

    d_slide: sliding thresholds [m] (a float or a sequence); shear_capacity: base shear [N] for
    the ``base_shear>V`` damage state (omitted when None); n_boot: bootstrap resamples per fit;
    boots: a list that receives ``(rack, im_measure, kind, state, (thetas, betas))`` per fit
    (the bootstrap samples, for the bands of the HTML report); hazard: a site hazard curve CSV
    in the study's intensity measure: adds ``risk`` (mean annual frequency and 50-year
    probability of each fitted fragility, :mod:`seisrack.studies.risk`).
    Returns the dict written to ``summary.json``.
    """
    out = Path(out_dir)
    if not out.is_dir():
        raise InputError("DIR", str(out), "a study output folder",
                         hint="Run `seisrack study STUDY.toml --out DIR` first")
    d_slide = (float(d_slide),) if np.isscalar(d_slide) else tuple(float(d) for d in d_slide)
    if not d_slide or any(not (d > 0) for d in d_slide):
        raise InputError("d_slide", d_slide, "one or more sliding thresholds > 0 [m]")
    check_distinct_thresholds("d_slide", d_slide)
    if shear_capacity is not None and not (shear_capacity > 0):
        raise InputError("shear_capacity", shear_capacity, "a base shear capacity > 0 [N]")
    from seisrack.studies.store import StoreError, check_parts, planned_stripes, read_study_json

    aside = check_parts(out)
    if aside:
        raise StoreError("; ".join(a.message() for a in aside) + f". Run the study again "
                         f"(seisrack study STUDY.toml --out {out}) to recompute them, then "
                         "summarise it")
    table = read_runs_table(out)
    if table.num_rows == 0:
        raise InputError("DIR", str(out), "a study folder with stored runs (runs/part-*.parquet)",
                         hint="The study has no finished run yet; run or resume it first")
    planned = planned_stripes(read_study_json(out))
    r, n_other = _of_this_study(runs_as_arrays(table), planned)
    if r["run_id"].size == 0:
        raise InputError("DIR", str(out), "a study folder with stored runs of the study its "
                         "study.json describes", hint=f"Its {n_other} stored runs belong to "
                         "another definition of the study; run the study of study.json "
                         f"(seisrack study STUDY.toml --out {out}) first")
    curve = None
    if hazard is not None:  # checked before any fit
        from seisrack.studies.risk import load_hazard_curve

        curve = load_hazard_curve(hazard, tuple(sorted(set(r["im_measure"]))))
    states = _damage_states(d_slide, shear_capacity)
    states_3d = _damage_states_3d(d_slide)
    status = r["status"]
    failed = status == "failed"
    reasons = Counter((e.splitlines()[0][:160] if e else "(no reason recorded)")
                      for e in r["error"][failed])
    summary: dict[str, Any] = {
        "out_dir": str(out), "runs_total": int(status.size),
        "runs_ok": int((status == "ok").sum()), "runs_left_out": n_other,
        "runs_failed": int(failed.sum()), "runs_skipped": int((status == "skipped").sum()),
        "failure_reasons": dict(reasons.most_common()),
        "d_slide_m": list(d_slide), "shear_capacity_N": shear_capacity, "n_boot": int(n_boot),
        "im_units": "m/s^2", "damage_states": [s[0] for s in states], "groups": [],
        "fragility": [],
        "warnings": _left_out(out, n_other, int(status.size))
        + _missing_runs(out, int(status.size), planned),
    }
    groups = sorted({(a, b) for a, b in zip(r["rack"], r["im_measure"], strict=True)})
    boot_store = []
    for rack, meas in groups:
        idx = np.flatnonzero((r["rack"] == rack) & (r["im_measure"] == meas))
        g: dict[str, Any] = {"rack": rack, "im_measure": meas}
        three_d = bool(np.isfinite(r["peak_sliding_cross_aisle_max_m"][idx]).any())
        g_states = states + (states_3d if three_d else [])
        if three_d:
            g["dimension"] = "3D"
            for name, *_ in states_3d:
                if name not in summary["damage_states"]:
                    summary["damage_states"].append(name)
        ms = idx[r["stripe"][idx] >= 0]
        ida = idx[r["stripe"][idx] < 0]
        if ms.size:
            g["stripes"] = _stripes(r, ms, g_states, n_boot, seed)
        if ida.size:
            g["ida"] = _ida(r, ida, g_states, n_boot, seed)
        red = reduction_summary(r, idx)
        if red is not None:
            g["sliding_reduction"] = red
        for kind in ("stripes", "ida"):
            for name, f in g.get(kind, {}).get("fragility", {}).items():
                boot_store.append((rack, meas, kind, name, f.pop("_boot", None)))
                row = {k: f[k] for k in CSV_FIELDS if k in f}
                summary["fragility"].append({"name": name, "rack": rack, "im_measure": meas,
                                             "analysis": kind, **row})
        summary["groups"].append(g)
    if curve is not None:
        from seisrack.studies.risk import risk_summary

        summary["risk"] = {"file": str(hazard), **risk_summary(curve, summary["fragility"])}
    from seisrack.studies.warehouse_summary import warehouse_groups, warehouse_summary

    wh = warehouse_groups(out)
    if wh is not None and "unreadable" in wh:
        summary["notes"] = [wh["unreadable"] + ": if the study is of a warehouse, its section "
                            "is missing; run the study command again to rewrite the file "
                            "(nothing is rerun)"]
    elif wh is not None:
        summary["warehouse"] = {**warehouse_summary(r, wh), "path": wh.get("path")}
        if hazard is not None:
            from seisrack.studies.warehouse_summary import annual_falls

            summary["warehouse"]["per_year"] = annual_falls(summary["warehouse"], curve)
    if boots is not None:
        boots.extend(boot_store)
    if write:
        _write(out / "summary", summary, plots=plots, boots=boot_store)
    return summary


def _of_this_study(r: dict[str, np.ndarray], planned: dict[str, int] | None
                   ) -> tuple[dict[str, np.ndarray], int]:
    """(the run arrays of the runs ``planned`` lists, with its stripe indices; the number of
    stored runs left out). ``planned``: run id -> stripe of ``study.json``; None keeps all.

    A stored run's own ``stripe`` is the index it had when it ran: a stripe inserted below it
    since then shifts the study's indices, so the study's are used.
    """
    if planned is None:
        return r, 0
    keep = np.fromiter((i in planned for i in r["run_id"]), dtype=bool, count=r["run_id"].size)
    r = {k: v[keep] for k, v in r.items()}
    r["stripe"] = np.array([planned[i] for i in r["run_id"]], dtype=float)
    return r, int(keep.size - keep.sum())


def _left_out(out: Path, n_other: int, n_kept: int) -> list[str]:
    """A warning when stored runs were left out as runs of another definition of the study."""
    if not n_other:
        return []
    return [f"{n_other} stored runs are left out: they are not runs of the study that "
            f"{out / 'study.json'} describes (another definition of the study was run into "
            f"this folder); the statistics describe its {n_kept} runs only"]


def _missing_runs(out: Path, n_stored: int, planned: dict[str, int] | None) -> list[str]:
    """A warning when the store holds fewer runs than ``study.json`` lists (an interrupted
    study, or part files set aside): the statistics then describe part of the study."""
    if planned is None or n_stored >= len(planned):
        return []
    n_planned = len(planned)
    return [f"the store holds {n_stored} of the study's {n_planned} runs: the statistics "
            f"describe part of the study; run it again (seisrack study STUDY.toml --out "
            f"{out}) to complete it"]


def _write(folder: Path, summary: dict[str, Any], *, plots: bool, boots) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    files = {"summary_json": str(folder / "summary.json"),
             "fragility_csv": str(folder / "fragility.csv")}
    def write_csv(path: Path) -> None:
        with open(path, "w", newline="", encoding="utf-8") as fh:
            w = csv.DictWriter(fh, fieldnames=list(CSV_FIELDS) + ["analysis"])
            w.writeheader()
            for row in summary["fragility"]:
                w.writerow({k: ("" if row.get(k) is None else row.get(k))
                            for k in w.fieldnames})

    atomic_write(folder / "fragility.csv", write_csv)
    if plots:
        files.update(_figures(folder, summary, boots))
        if "warehouse" in summary:
            from seisrack.studies.warehouse_summary import plan_figures

            files.update(plan_figures(folder, summary["warehouse"],
                                      summary["warehouse"].get("path")))
    summary["files"] = files
    write_text(folder / "summary.json", json.dumps(_jsonable(summary), indent=1,
                                                   allow_nan=False))


def _figures(folder: Path, summary: dict[str, Any], boots) -> dict[str, str]:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from seisrack.report.fragility_plot import plot_fragility, plot_ida

    files = {}
    ms = [g for g in summary["groups"] if "stripes" in g]
    if ms:
        fig, axes = plt.subplots(1, len(ms), figsize=(6.4 * len(ms), 4.4), squeeze=False)
        for ax, g in zip(axes[0], ms, strict=True):
            st = g["stripes"]["stripes"]
            im = np.array([s["im"] for s in st])
            grid = np.linspace(0.0, 1.6 * im.max(), 200)[1:]
            for name, f in g["stripes"]["fragility"].items():
                frac = [np.nan if s["fraction"][name] is None else s["fraction"][name] for s in st]
                th, be = next((b for rk, m, k, nm, b in boots if (rk, m, k, nm)
                               == (g["rack"], g["im_measure"], "stripes", name)), (None, None))
                band = fr.fragility_band(grid, th, be) if th is not None and th.size else None
                theta = math.nan if f["theta"] is None else f["theta"]
                beta = math.nan if f["beta"] is None else f["beta"]
                plot_fragility(im, frac, theta, beta, band=band, grid=grid, label=name,
                               im_label=f"{g['im_measure'].upper()} [m/s²]",
                               status=f.get("status"), ax=ax)
            ax.set_title(Path(g["rack"]).name, fontsize="small")
        fig.tight_layout()
        save_figure(fig, folder / "fragility.png", dpi=120)
        plt.close(fig)
        files["fragility_png"] = str(folder / "fragility.png")
    ida = [g for g in summary["groups"] if "ida" in g]
    if ida:
        fig, axes = plt.subplots(1, len(ida), figsize=(6.4 * len(ida), 4.4), squeeze=False)
        for ax, g in zip(axes[0], ida, strict=True):
            plot_ida(g["ida"]["curves"], im_label=f"{g['im_measure'].upper()} [m/s²]",
                     threshold=summary["d_slide_m"][0], ax=ax)
            ax.set_title(Path(g["rack"]).name, fontsize="small")
        fig.tight_layout()
        save_figure(fig, folder / "ida.png", dpi=120)
        plt.close(fig)
        files["ida_png"] = str(folder / "ida.png")
    from seisrack.report.study_figures import save_reduction_figure, save_risk_figure

    files.update(save_reduction_figure(folder, summary))
    files.update(save_risk_figure(folder, summary))
    return files


def _jsonable(obj: Any) -> Any:
    """Non-finite floats -> None (JSON has no NaN), numpy scalars -> Python, recursively."""
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def _fmt(x: Any, spec: str = ".3g") -> str:
    return "-" if x is None else format(x, spec)


def format_summary(s: dict[str, Any]) -> str:
    """A readable text summary of :func:`summarize`'s result."""
    lines = [f"warning: {w}" for w in s.get("warnings", [])]
    lines += [f"study {s['out_dir']}: {s['runs_total']} runs, {s['runs_ok']} ok, "
             f"{s['runs_failed']} failed" + (f", {s['runs_skipped']} skipped (IDA stop rule)"
                                              if s.get("runs_skipped") else "")]
    for reason, n in s["failure_reasons"].items():
        lines.append(f"  failed x{n}: {reason}")
    for g in s["groups"]:
        lines.append(f"\nrack {g['rack']}, IM = {g['im_measure']} [m/s²]")
        if "stripes" in g:
            three_d = g.get("dimension") == "3D"
            # at risk: down-aisle sliding reached the free distance (pallets_at_risk)
            lines.append("  stripe      IM   ok/runs  records  sliding mean/max [m]  at risk (mean)"
                         + ("  fell into an aisle (mean)" if three_d else ""))
            for st in g["stripes"]["stripes"]:
                pk = st["peaks"]["peak_sliding_max_m"]
                nf = st["peaks"]["n_fall"]
                na = st["peaks"].get("n_aisle_fall") or {"mean": None}
                lines.append(f"  {st['stripe']:6d} {st['im']:7.3g} "
                             f"{st['n_ok']:4d}/{st['n_runs']:<4d} {st['n_records']:7d}  "
                             f"{_fmt(pk['mean']):>9} / {_fmt(pk['max']):<9}"
                             f" {_fmt(nf['mean']):>14}"
                             + (f"  {_fmt(na['mean']):>26}" if three_d else ""))
        if "ida" in g:
            lines.append(f"  IDA: {len(g['ida']['curves'])} curves")
        if "sliding_reduction" in g:
            lines += format_reduction(g["sliding_reduction"])
    lines.append("\nfragility (theta [m/s²], beta; 90 % bootstrap band)")
    for f in s["fragility"]:
        lines.append(f"  {f['analysis']:7s} {f['name']:22s} theta {_fmt(f['theta']):>7} "
                     f"[{_fmt(f['theta_lo'])}, {_fmt(f['theta_hi'])}]  beta {_fmt(f['beta']):>6} "
                     f"[{_fmt(f['beta_lo'])}, {_fmt(f['beta_hi'])}]  {f['status']}")
    notes = {
        "separated": "separated: the stripes jump from no exceedance to exceedance without "
                     "enough stripes in between; the MLE is a step (beta = 0). Add stripes "
                     "around theta to estimate the dispersion.",
        "underdetermined": "underdetermined: one stripe carries all the information; theta "
                           "and beta cannot both be estimated.",
        "no_exceedance": "no_exceedance: no run reached the state; raise the stripes.",
        "all_exceed": "all_exceed: every run reached the state; lower the stripes.",
        "failed": "failed: the likelihood has no maximum in range (e.g. fractions decreasing "
                  "with IM).",
        "ida_censored": "ida_censored: some IDA curves never reached the state and were left "
                        "out (theta is biased low).",
    }
    seen = [st for st in notes if any(f["status"] == st for f in s["fragility"])]
    lines += [f"  note: {notes[st]}" for st in seen]
    if "risk" in s:
        from seisrack.studies.risk import format_risk

        lines += format_risk(s["risk"])
    lines += [f"\nnote: {n}" for n in s.get("notes", [])]
    if "warehouse" in s:
        from seisrack.studies.warehouse_summary import format_warehouse

        lines += format_warehouse(s["warehouse"])
    if "files" in s:
        lines.append("\nwritten: " + ", ".join(s["files"].values()))
    return "\n".join(lines)
