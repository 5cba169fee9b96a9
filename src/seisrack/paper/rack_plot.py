"""Figures of the paper report's §IV: Fig. 15 (record and spectrum), Fig. 16 (histories) and a
summary of the physics checks. matplotlib is imported lazily; nothing is shown."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from seisrack.atomic import save_figure
from seisrack.motion.records import G as G_REC
from seisrack.paper import values as pv
from seisrack.paper.rack import RackRun, RackStudy, table_row
from seisrack.paper.sections import pyplot

__all__ = ["save_fig15", "save_fig16", "save_physics_figure"]


def save_fig15(st: RackStudy, path: Path) -> Path:
    """(a) the accelerogram, (b) its 5 % spectrum against the EC8 target (Fig. 15a/b)."""
    from seisrack.report.motion_plot import plot_accelerogram, plot_spectrum

    plt = pyplot()
    fig, (ax_a, ax_b) = plt.subplots(2, 1, figsize=(9, 7.5))
    plot_accelerogram(st.main.record, ax=ax_a)
    ax_a.set_title(f"(a) synthetic EC8 Type 1, ground C, ag = 0.3 g, seed "
                   f"{st.main.record.meta.get('seed')} — PGA "
                   f"{st.main.record.pga / G_REC:.3f} g", fontsize=10)
    plot_spectrum(st.periods, st.psa_5, ax=ax_b, target=st.target, label="record, 5 %")
    ax_b.plot(st.periods, st.psa_struct / G_REC, "C1:", lw=1.0,
              label=f"record, {100 * st.damping_ratio:.0f} % (rack damping)")
    ax_b.axvline(st.t1, color="0.4", lw=0.8)
    ax_b.text(st.t1, ax_b.get_ylim()[1] * 0.97, f" T1 = {st.t1:.3f} s", va="top", fontsize=9)
    ax_b.set_xscale("log")
    ticks = [0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 4]
    ax_b.set_xticks(ticks, [f"{x:g}" for x in ticks])
    ax_b.set_title("(b) response spectrum of the record and EC8 target (η = 5 %)", fontsize=10)
    ax_b.legend(fontsize="small")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


def _overlay(runs: dict[str, object], key: str, ax: object) -> None:
    try:
        from seisrack.report.rack_plot import plot_rack_histories
    except ImportError:  # pragma: no cover - the colleague's module is absent
        plot_rack_histories = None
    if plot_rack_histories is not None:
        plot_rack_histories(runs, key, ax)  # type: ignore[arg-type]
        return
    scale = {"beam_displacement": 1e3, "beam_acceleration": 1.0, "contact_force": 1e-3,
             "pallet_sliding": 1e3}[key]
    for lab, r in runs.items():
        y = getattr(r, key)
        y = y.sum(axis=1) if key == "contact_force" else y[:, 0]
        ax.plot(r.t, y * scale, lw=0.8, label=lab)  # type: ignore[attr-defined]
    ax.legend(fontsize=8)  # type: ignore[attr-defined]


def save_fig16(rs: RackRun, path: Path, title: str) -> Path:
    """Fig. 16a–d: beam displacement, beam acceleration, total contact force, sliding of one
    pallet, the four μ overlaid."""
    plt = pyplot()
    fig, axes = plt.subplots(4, 1, figsize=(10, 12.5), sharex=True)
    runs = {f"μ = {mu:.2f}": r for mu, r in rs.runs.items()}
    keys = ("beam_displacement", "beam_acceleration", "contact_force", "pallet_sliding")
    for ax, key, letter in zip(axes, keys, "abcd", strict=True):
        _overlay(runs, key, ax)
        ax.set_title(f"({letter}) " + ax.get_title(), fontsize=10)
        if letter != "d":
            ax.set_xlabel("")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    save_figure(fig, path, dpi=100)
    plt.close(fig)
    return path


def save_physics_figure(st: RackStudy, path: Path) -> Path:
    """(a) peak force / (M g) against μ for every record: the cap μ up to the onset Se(T1)/g;
    (b) peak displacement against peak force, all runs, with the paper's Table 2."""
    plt = pyplot()
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(12, 4.8))
    mg = st.spec.pallet_mass_total * st.main.g
    mus = np.array(pv.MU_VALUES)
    sets = list(st.suite) + ([st.sensitivity] if st.sensitivity else [])
    for k, rs in enumerate(sets):
        sens = rs is st.sensitivity
        held = table_row(rs.rigid)["force_N"] / mg
        f = [table_row(rs.runs[m])["force_N"] / mg for m in mus]
        style = {"c": "C3", "lw": 1.4} if sens else {"c": "C0", "lw": 0.7, "alpha": 0.6}
        lab = (f"ζ = {100 * rs.damping_ratio:.0f} %, main record" if sens else
               (f"ζ = {100 * rs.damping_ratio:.0f} %, {len(st.suite)} records" if k == 0 else
                None))
        # between the runs: F = mu M g up to the onset, then the held value (no sliding)
        xs = sorted([*mus[mus < rs.onset_mu], rs.onset_mu, 1.6])
        ys = [min(x, rs.onset_mu) if x <= rs.onset_mu else held for x in xs]
        ax_a.plot(xs, ys, label=lab, **style)
        ax_a.plot(np.append(mus, 1.6), [*f, held], "s" if sens else "o", ms=3.5, c=style["c"])
        ax_a.plot([rs.se_t1 / rs.g], [rs.se_t1 / rs.g], marker="x", c=style["c"], ms=8, mew=1.5)
    ax_a.plot([0, 1.6], [0, 1.6], "k--", lw=0.8, label="cap: F = μ M g")
    ax_a.plot(list(pv.TABLE2), [v[2] / (pv.PALLET_MASS_KG * pv.TABLE2_G)
                                for v in pv.TABLE2.values()], "k^", ms=7, mfc="none",
              label="paper Table 2")
    ax_a.set_xlabel("μ  (1.6 = pallets held)")
    ax_a.set_ylabel("peak total contact force / (M g)")
    ax_a.set_title("(a) force cut by sliding (markers: runs; lines: cap up to the onset)\n"
                   "×: Se(T1, ζ)/g of each record", fontsize=10)
    ax_a.legend(fontsize="small", loc="upper left")
    ax_a.grid(True, alpha=0.3)
    ax_a.set_xlim(0, 1.65)
    ax_a.set_ylim(0, 1.65)

    rows = [table_row(r) for rs in sets for r in list(rs.runs.values()) + [rs.rigid]]
    fx = np.array([r["force_N"] for r in rows]) * 1e-3
    dx = np.array([r["disp_m"] for r in rows]) * 1e3
    k = float(np.sum(dx * fx) / np.sum(fx * fx))
    ax_b.plot(fx, dx, "o", c="C0", ms=3.5, alpha=0.7, label="seisrack, all runs")
    xx = np.array([0, fx.max() * 1.05])
    ax_b.plot(xx, k * xx, "C0-", lw=0.8, label=f"fit through 0: {1e3 / k:.0f} kN/m")
    ax_b.plot([v[2] * 1e-3 for v in pv.TABLE2.values()], [v[0] * 1e3 for v in pv.TABLE2.values()],
              "k^", ms=7, mfc="none", label="paper Table 2")
    ax_b.set_xlabel("peak total contact force [kN]")
    ax_b.set_ylabel("peak beam displacement [mm]")
    ax_b.set_title("(b) displacement proportional to force (one mode)", fontsize=10)
    ax_b.legend(fontsize="small", loc="upper left")
    ax_b.grid(True, alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path, dpi=100)
    plt.close(fig)
    return path
