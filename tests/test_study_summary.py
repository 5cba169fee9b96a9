"""Study summary on synthetic stores: counts, EC8 means, fragility fits (Baker 2015), CLI.

Source of the fits: J. W. Baker (2015), "Efficient analytical fragility function fitting using
dynamic structural analysis", Earthquake Spectra 31(1), 579-599 (binomial likelihood on stripes,
Eq. 11; method of moments on IDA). EC8 means: EN 1998-1 §4.3.3.4.3 (mean over >= 7 records,
else the maximum).

The stores are written here with pyarrow in the layout of ``seisrack study --out DIR``
(``DIR/runs/part-*.parquet``, one row per run), with known counts per stripe, so the summary's
numbers are checked against independent fits of the same counts, hand-computed means, and the
failures planted in the store. One run is stored twice to check it counts once.
"""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

pa = pytest.importorskip("pyarrow")
pq = pytest.importorskip("pyarrow.parquet")

from seisrack.cli import main  # noqa: E402
from seisrack.errors import InputError  # noqa: E402
from seisrack.studies import fragility as fr  # noqa: E402
from seisrack.studies.summary import summarize  # noqa: E402


def summary_main(argv: list[str]) -> int:
    """``seisrack study summary ARGV`` through the command line's error boundary."""
    return main(["study", "summary", *argv])


IMS = (1.0, 2.0, 3.0, 4.0)  # [m/s²]
N_REC, N_MU = 8, 2
THETA, BETA = 2.5, 0.4


def _row(i, **kw):
    base = {"run_id": f"r{i:05d}", "rack": "paper.toml", "record": "rec0", "im_measure": "pga",
            "im_target": 1.0, "scale_factor": 1.0, "stripe": 0, "mu_static": 0.4,
            "mu_dynamic": 0.4, "occupancy": 1.0, "seed": 7, "status": "ok", "error": "",
            "peak_sliding_max_m": 0.0, "pallet_peak_sliding_m": [0.0, 0.0], "n_pallets": 2,
            "any_fall": False, "n_fall": 0, "base_shear_N": 0.0,
            "beam_displacement_max_m": 0.0, "drift_ratio_max": 0.0,
            "upright_moment_connection_Nm": 0.0, "wall_time_s": 0.01}
    base.update(kw)
    return base


def _write(tmp, rows, parts=2):
    runs = tmp / "runs"
    runs.mkdir(parents=True, exist_ok=True)
    for p, chunk in enumerate(np.array_split(np.arange(len(rows)), parts)):
        sel = [rows[i] for i in chunk]
        tbl = pa.table({k: [r[k] for r in sel] for k in sel[0]})
        pq.write_table(tbl, runs / f"part-{p:03d}.parquet")
    (tmp / "study.json").write_text("{}")


@pytest.fixture
def stripes_store(tmp_path):
    """4 stripes x 8 records x 2 friction samples; sliding = IM-driven lognormal capacity."""
    rng = np.random.default_rng(11)
    rows = []
    i = 0
    for s, x in enumerate(IMS):
        for rec in range(N_REC):
            for m in range(N_MU):
                cap = THETA * math.exp(BETA * rng.standard_normal())
                slide = 0.05 * x / cap  # exceeds 0.05 m exactly when x > capacity
                rows.append(_row(i, record=f"rec{rec}", im_target=x, stripe=s,
                                 mu_static=0.3 + 0.1 * m, peak_sliding_max_m=slide,
                                 any_fall=bool(slide > 0.1), n_fall=int(slide > 0.1),
                                 base_shear_N=1000.0 * x + rec))
                i += 1
    # failures: two at stripe 3 (a solver status and a bad record), one without a reason
    for j, err in enumerate(["solver: max events exceeded", "record: NaN in accelerogram",
                             "solver: max events exceeded"]):
        rows.append(_row(i + j, record="recX", im_target=IMS[3], stripe=3, status="failed",
                         error=err, peak_sliding_max_m=None, pallet_peak_sliding_m=None,
                         any_fall=None, n_fall=None, base_shear_N=None))
    rows.append(dict(rows[0]))  # stored twice (a resumed study): counted once
    _write(tmp_path, rows)
    return tmp_path, rows[:-1]


def _counts(rows, pred):
    n, k = [], []
    for s in range(len(IMS)):
        ok = [r for r in rows if r["stripe"] == s and r["status"] == "ok"]
        n.append(len(ok))
        k.append(sum(pred(r) for r in ok))
    return np.array(n), np.array(k)


def test_counts_and_fits_match_independent_fit(stripes_store):
    out, rows = stripes_store
    s = summarize(out, d_slide=[0.05, 0.1], shear_capacity=3500.0, n_boot=60, seed=1)
    assert s["runs_total"] == len(rows) == 4 * N_REC * N_MU + 3
    assert s["runs_ok"] == 4 * N_REC * N_MU and s["runs_failed"] == 3
    assert s["failure_reasons"] == {"solver: max events exceeded": 2,
                                    "record: NaN in accelerogram": 1}
    (g,) = s["groups"]
    st = g["stripes"]["stripes"]
    assert [x["im"] for x in st] == list(IMS)
    assert [x["n_failed"] for x in st] == [0, 0, 0, 3]
    assert all(x["n_ok"] == N_REC * N_MU and x["n_records"] == N_REC for x in st)
    fits = g["stripes"]["fragility"]
    assert set(fits) == {"sliding>0.05m", "sliding>0.1m", "any_fall", "base_shear>3500N"}
    for name, pred in [("sliding>0.05m", lambda r: r["peak_sliding_max_m"] > 0.05),
                       ("any_fall", lambda r: r["any_fall"])]:
        n, k = _counts(rows, pred)
        ref = fr.fit_fragility(IMS, n, k)
        assert fits[name]["theta"] == pytest.approx(ref.theta, rel=1e-9)
        assert fits[name]["beta"] == pytest.approx(ref.beta, rel=1e-9)
        assert fits[name]["n_runs"] == n.sum() and fits[name]["n_stripes"] == 4
        assert fits[name]["theta_lo"] <= ref.theta <= fits[name]["theta_hi"]
        assert fits[name]["beta_lo"] <= ref.beta <= fits[name]["beta_hi"]
        assert [x["fraction"][name] for x in st] == pytest.approx(list(k / n))
    # the planted capacity is recovered within about two standard errors
    f = fits["sliding>0.05m"]
    assert abs(math.log(f["theta"] / THETA)) < 2.5 * f["se_ln_theta"]
    # base shear = 1000 IM + record index: all-or-nothing around 3.5 m/s², a step
    assert fits["base_shear>3500N"]["status"] == "separated"
    assert fits["base_shear>3500N"]["theta"] == pytest.approx(math.sqrt(3.0 * 4.0))


def test_ec8_means_and_outputs(stripes_store):
    out, rows = stripes_store
    s = summarize(out, n_boot=20)
    st = s["groups"][0]["stripes"]["stripes"][1]
    ok = [r for r in rows if r["stripe"] == 1 and r["status"] == "ok"]
    per_rec = [np.mean([r["peak_sliding_max_m"] for r in ok if r["record"] == f"rec{j}"])
               for j in range(N_REC)]
    pk = st["peaks"]["peak_sliding_max_m"]
    assert pk["mean"] == pytest.approx(np.mean(per_rec))
    assert pk["max"] == pytest.approx(np.max(per_rec))
    assert pk["ec8"] == pk["mean"]  # 8 records >= 7: EC8 takes the mean
    summ = out / "summary"
    doc = json.loads((summ / "summary.json").read_text())
    assert doc["runs_total"] == s["runs_total"]
    with open(summ / "fragility.csv") as fh:
        rows_csv = list(csv.DictReader(fh))
    assert [r["name"] for r in rows_csv] == ["sliding>0.05m", "any_fall"]
    assert float(rows_csv[0]["theta"]) == pytest.approx(s["fragility"][0]["theta"])
    for col in ("theta_lo", "theta_hi", "beta_lo", "beta_hi", "n_stripes", "n_runs"):
        assert rows_csv[0][col] != ""
    assert (summ / "fragility.png").stat().st_size > 5000


def test_fewer_than_seven_records_takes_the_max(tmp_path):
    rows = [_row(i, record=f"rec{i % 3}", im_target=2.0, peak_sliding_max_m=0.01 * (i % 3 + 1))
            for i in range(6)]
    _write(tmp_path, rows, parts=1)
    st = summarize(tmp_path, n_boot=0, plots=False)["groups"][0]["stripes"]["stripes"][0]
    pk = st["peaks"]["peak_sliding_max_m"]
    assert st["n_records"] == 3 and pk["ec8"] == pytest.approx(0.03) == pk["max"]
    assert pk["mean"] == pytest.approx(0.02)


def test_ida_curves_and_moments(tmp_path):
    steps = np.array([0.5, 1.0, 1.5, 2.0, 2.5, 3.0])
    caps = [1.2, 1.7, 2.2, 0.8, 2.7, 1.4, 1.9]  # IM at which sliding reaches 0.05 m
    rows, i = [], 0
    for rec, c in enumerate(caps):
        for x in steps:
            rows.append(_row(i, record=f"rec{rec}", stripe=-1, im_target=float(x),
                             peak_sliding_max_m=0.05 * x / c))
            i += 1
    _write(tmp_path, rows)
    s = summarize(tmp_path, n_boot=50)
    ida = s["groups"][0]["ida"]
    assert len(ida["curves"]) == len(caps)
    assert ida["curves"][0]["im"] == steps.tolist()
    f = ida["fragility"]["sliding>0.05m"]
    # linear interpolation between steps recovers c exactly (sliding is linear in IM)
    np.testing.assert_allclose(f["capacities"], caps, rtol=1e-12)
    assert f["theta"] == pytest.approx(math.exp(np.mean(np.log(caps))))
    assert f["beta"] == pytest.approx(np.std(np.log(caps), ddof=1))
    assert f["theta_lo"] < f["theta"] < f["theta_hi"]
    assert ida["fragility"]["any_fall"]["status"] == "no_exceedance"
    assert (tmp_path / "summary" / "ida.png").exists()
    assert not (tmp_path / "summary" / "fragility.png").exists()


def test_summary_main_json(stripes_store, capsys):
    out, rows = stripes_store
    code = summary_main([str(out), "--d-slide", "0.05", "--boot", "20", "--json",
                         "--shear-capacity", "3500"])
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    assert (doc["runs_total"], doc["runs_ok"], doc["runs_failed"]) == (len(rows), 64, 3)
    names = {f["name"]: f for f in doc["fragility"]}
    assert set(names) == {"sliding>0.05m", "any_fall", "base_shear>3500N"}
    assert names["sliding>0.05m"]["theta"] > 0 and names["sliding>0.05m"]["beta"] > 0


def test_summary_main_text(stripes_store, capsys):
    out, _ = stripes_store
    assert summary_main([str(out), "--boot", "10", "--no-plots"]) == 0
    text = capsys.readouterr().out
    assert "67 runs, 64 ok, 3 failed" in text and "sliding>0.05m" in text


@pytest.mark.parametrize("case", ["missing", "empty", "no_parts", "bad_d", "same_d"])
def test_summary_main_bad_input(tmp_path, capsys, case):
    target = tmp_path / "study"
    args = [str(target)]
    if case == "empty":
        target.mkdir()
    elif case == "no_parts":
        (target / "runs").mkdir(parents=True)
    elif case == "bad_d":
        _write(target, [_row(0)], parts=1)
        args += ["--d-slide", "-1"]
    elif case == "same_d":  # one damage state name twice: its counts were pooled
        _write(target, [_row(0)], parts=1)
        args += ["--d-slide", "0.05", "0.05000000001"]
    code = summary_main(args)
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("seisrack: error:") and "Traceback" not in err
    assert err.count("\n") == 1
    assert ("--d-slide" in err) if case.endswith("_d") else (str(target) in err)
    if case == "same_d":
        assert "0.05 m is given twice" in err
        with pytest.raises(InputError, match="d_slide"):
            summarize(target, d_slide=[0.1, 0.1])


def test_local_reader_dedups_and_sorts(tmp_path):
    """The fallback reader (used when the store module is absent) keeps one row per run_id."""
    from seisrack.studies.summary import _read_runs_local

    rows = [_row(i, peak_sliding_max_m=0.01 * i) for i in (3, 1, 2)]
    _write(tmp_path, rows + [dict(rows[1])], parts=2)
    table = _read_runs_local(tmp_path)
    assert table.column("run_id").to_pylist() == ["r00001", "r00002", "r00003"]
    assert _read_runs_local(tmp_path / "nowhere").num_rows == 0


def test_example_study_gives_a_proper_fragility(tmp_path) -> None:
    """The shipped example (issue 13) brackets the sliding onset: every fit is an ordinary
    lognormal (status ok, 0 < beta), not a step, and theta lies inside the stripes."""
    from pathlib import Path

    from seisrack.studies import load_study, run_study
    from seisrack.studies.summary import summarize

    example = Path(__file__).resolve().parents[1] / "examples" / "study_paper_rack.toml"
    out = tmp_path / "study"
    run_study(load_study(example), out, workers=2, progress=False)
    s = summarize(out, n_boot=50, plots=False)
    assert (s["runs_total"], s["runs_ok"], s["runs_failed"]) == (72, 72, 0)
    fits = s["fragility"]
    assert fits and all(f["status"] == "ok" for f in fits)
    g = 9.80665
    assert all(0.0 < f["beta"] < 1.0 and 0.3 * g < f["theta"] < 0.5 * g for f in fits)
