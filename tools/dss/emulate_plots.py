"""The emulator's PNG plots: the run-up over (reservoir level, phi) with its uncertainty, the
cross-validation's predicted vs simulated, the exceedance curve with its band, Sobol indices."""

from __future__ import annotations

import os

import numpy as np

from . import emulator as E


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def surface(em: E.Emulator, output: str, path: str, x="reservoir_level", y="phi",
            fixed: dict | None = None, n=41):
    """Mean over (x, y) with the 95 % half-width as contour lines, one column per level of the
    binary inputs; below, slices over x at three y values with their 95 % bands. The other
    inputs at `fixed` or the middle of their box."""
    plt = _plt()
    if x not in em.inputs or y not in em.inputs:
        raise E.EmulatorError(f"the surface needs inputs {x} and {y} (the emulator has "
                              f"{', '.join(em.inputs)})")
    fixed = dict(fixed or {})
    bins = [n_ for n_, k in zip(em.inputs, em.kinds) if k == "binary" and n_ not in fixed]
    levels = [dict(zip(bins, v)) for v in np.ndindex(*([2] * len(bins)))] if bins else [{}]
    levels = levels[:4]
    ix, iy = em.inputs.index(x), em.inputs.index(y)
    gx = np.linspace(*em.box[ix], n)
    gy = np.linspace(*em.box[iy], n)
    GX, GY = np.meshgrid(gx, gy)
    base = {nm: fixed.get(nm, 0.5 * (b[0] + b[1])) for nm, b in zip(em.inputs, em.box)}
    fig, axes = plt.subplots(2, len(levels), figsize=(5.2 * len(levels), 8.4), squeeze=False)
    res = []
    for c, lv in enumerate(levels):
        rows = []
        for xv, yv in zip(GX.ravel(), GY.ravel()):
            r = dict(base)
            r.update(lv)
            r[x], r[y] = xv, yv
            rows.append(r)
        mu, sd = em.predict(em.matrix(rows), [output])[output]
        res.append((mu, sd))
        ax = axes[0, c]
        cs = ax.contourf(GX, GY, mu.reshape(GX.shape), 14, cmap="viridis")
        fig.colorbar(cs, ax=ax, label=f"{output} (mean)")
        cl = ax.contour(GX, GY, (E.Z95 * sd).reshape(GX.shape), 5, colors="w", linewidths=0.8,
                        linestyles="--")
        ax.clabel(cl, fmt="±%.3g", fontsize=7)
        m = em.models[output]
        rows_t, _ = em._rows(output)
        Xt = em.X[rows_t]
        sel = np.ones(len(Xt), bool)
        for nm, v in lv.items():
            sel &= Xt[:, em.inputs.index(nm)] == v
        ax.plot(Xt[sel, ix], Xt[sel, iy], "k.", ms=4, label="training runs")
        ttl = ", ".join(f"{k}={v}" for k, v in lv.items()) or "all"
        ax.set_title(f"{ttl}: mean, dashed: 95 % half-width", fontsize=9)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        ax.legend(loc="lower right", fontsize=7)
        ax2 = axes[1, c]
        for yv, col in zip(np.quantile(gy, [0.0, 0.5, 1.0]), ("C0", "C1", "C2")):
            rows = []
            for xv in gx:
                r = dict(base)
                r.update(lv)
                r[x], r[y] = xv, yv
                rows.append(r)
            mu1, sd1 = em.predict(em.matrix(rows), [output])[output]
            ax2.plot(gx, mu1, color=col, label=f"{y} = {yv:.3g}")
            ax2.fill_between(gx, mu1 - E.Z95 * sd1, mu1 + E.Z95 * sd1, color=col, alpha=0.25)
        ax2.set_xlabel(x)
        ax2.set_ylabel(f"{output} (mean, 95 % band)")
        ax2.set_title(f"{ttl}: slices; others at " + ", ".join(
            f"{k}={v:.3g}" for k, v in base.items() if k not in (x, y) and k not in lv),
            fontsize=8)
        ax2.legend(fontsize=7)
        ax2.grid(alpha=0.3)
        del m
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def cv_plot(cv: dict, output: str, path: str, title: str = "cross-validation",
            holdout: dict | None = None):
    """Predicted (out-of-fold mean, 95 % interval) against simulated."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.6, 5.2))
    sets = [(title, cv, "C0")] + ([("hold-out", holdout, "C3")] if holdout else [])
    lo = hi = None
    for label, d, col in sets:
        y, mu, sd = (np.asarray(d[k], float) for k in ("y", "mean", "sd"))
        inside = np.abs(mu - y) <= E.Z95 * sd
        ax.errorbar(y, mu, yerr=E.Z95 * sd, fmt="o", ms=4, color=col, alpha=0.8, lw=0.8,
                    label=f"{label}: n {len(y)}, RMSE {d['rmse_pct']:.2f} %, max "
                          f"{d['max_error_pct']:.2f} % of range, {100 * inside.mean():.0f} % inside")
        lo = min(y.min(), (mu - E.Z95 * sd).min()) if lo is None else min(lo, y.min())
        hi = max(y.max(), (mu + E.Z95 * sd).max()) if hi is None else max(hi, y.max())
    ax.plot([lo, hi], [lo, hi], "k-", lw=0.8)
    ax.set_xlabel(f"{output}, FMU")
    ax.set_ylabel(f"{output}, emulator (mean, 95 % interval)")
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def exceedance_plot(risk: dict, path: str):
    plt = _plt()
    c = risk["curve"]
    fig, ax = plt.subplots(figsize=(6, 4.2))
    ax.fill_between(c["z"], c["lo"], c["hi"], color="C0", alpha=0.3,
                    label="95 % band (emulator uncertainty)")
    ax.plot(c["z"], c["p"], "C0-", label="P(exceed), emulator")
    ax.plot(c["z"], c["mean_only"], "k:", lw=0.8, label="from the mean only")
    ax.axvline(risk["crest"], color="C3", ls="--",
               label=f"crest {risk['crest']:g}: P = {risk['p']:.3f} "
                     f"[{risk['p_lo']:.3f}, {risk['p_hi']:.3f}]")
    ax.set_xlabel(risk["output"])
    ax.set_ylabel("exceedance probability")
    ax.set_ylim(0, 1)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def sobol_plot(s: dict, output: str, path: str):
    plt = _plt()
    names = s["names"]
    x = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(1.4 * len(names) + 2.5, 3.8))
    ax.bar(x - 0.2, s["S1"], 0.4, yerr=s["S1_conf"], label="first order S1", capsize=3)
    ax.bar(x + 0.2, s["ST"], 0.4, yerr=s["ST_conf"], label="total ST", capsize=3)
    ax.set_xticks(x, names, rotation=15)
    ax.set_ylabel(f"Sobol index of {output}")
    ax.axhline(0, color="k", lw=0.6)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def design_history(history: list[dict], path: str, target=None, other: dict | None = None):
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 4))
    h = [r for r in history if "rmse_pct" in r]
    ax.plot([r["runs"] for r in h], [r["rmse_pct"] for r in h], "o-", ms=3, label="CV RMSE")
    ax.plot([r["runs"] for r in h], [r["max_error_pct"] for r in h], "s--", ms=3,
            label="CV max error")
    if target is not None:
        ax.axhline(target, color="C3", ls=":", label=f"target {target:g} %")
    ax.set_xlabel("FMU runs")
    ax.set_ylabel("% of the output's range")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def curve_plot(rows: list[dict], path: str):
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 4))
    d = [r for r in rows if r["set"] == "design"]
    ax.plot([r["runs"] for r in d], [r["rmse_pct"] for r in d], "o-", color="C0",
            label="design: hold-out RMSE")
    ax.plot([r["runs"] for r in d], [r["max_error_pct"] for r in d], "s--", color="C0",
            label="design: hold-out max error")
    for i, r in enumerate([r for r in rows if r["set"] != "design"]):
        ax.plot([r["runs"]], [r["rmse_pct"]], "o", color=f"C{i + 1}", ms=8,
                label=f"{r['set']}: RMSE")
        ax.plot([r["runs"]], [r["max_error_pct"]], "s", color=f"C{i + 1}", ms=8,
                label=f"{r['set']}: max")
    ax.axhline(2, color="k", ls=":", lw=0.8)
    ax.axhline(5, color="k", ls="-.", lw=0.8)
    ax.set_xlabel("FMU runs fitted")
    ax.set_ylabel("% of the run-up's range")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def ensure_dir(path):
    d = os.path.dirname(path)
    if d:
        os.makedirs(d, exist_ok=True)


def jitter_plot(doc: dict, output: str, path: str):
    """The jitter scan: the output against the first perturbed input's offset, per point, with
    the fitted linear trend and the estimated noise sd."""
    plt = _plt()
    runs, est = doc["runs"], doc["outputs"][output]
    names = list(doc["settings"]["perturb"])
    off = np.array(runs["offsets"], dtype=float)[:, 0]
    y = np.array(runs[output], dtype=float)
    g = np.array(runs["group"])
    fig, ax = plt.subplots(figsize=(6, 4))
    for i, k in enumerate(np.unique(g)):
        s = g == k
        pt = doc["settings"]["points"][int(k)]
        lab = ", ".join(f"{n}={v:g}" for n, v in pt.items() if n not in names)
        ax.plot(1e3 * off[s], y[s], "o", color=f"C{i}", label=lab or "runs")
        o = np.sort(off[s])
        # the fitted trend of this point (residuals: y - fit)
        fit = y[s] - np.array(est["residuals"])[s]
        c = np.polyfit(off[s], fit, 1)
        ax.plot(1e3 * o, np.polyval(c, o), "-", color=f"C{i}", lw=0.8)
    ax.set_xlabel(f"offset of {names[0]} (mm)")
    ax.set_ylabel(output)
    ax.set_title(f"jitter scan at dx = {doc['settings']['dx']:g}: noise sd {est['sd']:.3g} "
                 f"(95 % CI {est['ci95_sd'][0]:.2g}-{est['ci95_sd'][1]:.2g}, {est['dof']} dof)",
                 fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def mf_validation_plot(doc: dict, output: str, path: str):
    """Predicted (with the 95 % intervals) against simulated hold-out runs at one level."""
    plt = _plt()
    y, mu, sd = (np.asarray(doc[k], float) for k in ("y", "mean", "sd"))
    met = doc["metrics"]
    fig, ax = plt.subplots(figsize=(5, 4.6))
    inside = np.abs(mu - y) <= E.Z95 * sd
    ax.errorbar(y[inside], mu[inside], yerr=E.Z95 * sd[inside], fmt="o", ms=4, color="C0",
                capsize=2, label="inside its 95 % interval")
    if (~inside).any():
        ax.errorbar(y[~inside], mu[~inside], yerr=E.Z95 * sd[~inside], fmt="s", ms=4,
                    color="C3", capsize=2, label="outside")
    lo = min(y.min(), (mu - E.Z95 * sd).min())
    hi = max(y.max(), (mu + E.Z95 * sd).max())
    ax.plot([lo, hi], [lo, hi], "k-", lw=0.7)
    ax.set_xlabel(f"{output}, FMU at dx = {doc['holdout_dx']:g}")
    ax.set_ylabel(f"emulator, level {doc['level']}")
    ax.set_title(f"RMSE {met['rmse']:.3g} ({met['rmse_pct']:.1f} % of range), "
                 f"{100 * met['coverage95']:.0f} % inside", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def mf_design_history(state: dict, path: str):
    """The multi-fidelity design: the CPU spent and the runs per level against the batches,
    and the finest level's leave-one-out RMSE."""
    plt = _plt()
    h = state["history"]
    levels = state["spec"]["levels"]
    cpu = [x["cpu_spent_s"] for x in h]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.8))
    runs = np.array([x["runs_per_level"] for x in h])
    for j, dx in enumerate(levels):
        a1.plot(cpu, runs[:, j], "o-", ms=3, label=f"dx {dx:g}")
    a1.set_xlabel("CPU seconds spent")
    a1.set_ylabel("runs")
    a1.legend(fontsize=7)
    a1.grid(alpha=0.3)
    a2.plot(cpu, [x["loo_rmse_finest"] for x in h], "o-", ms=3, color="C3")
    a2.set_xlabel("CPU seconds spent")
    a2.set_ylabel(f"LOO RMSE at dx {levels[-1]:g}")
    a2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def level_costs(df, levels, path: str):
    """The CPU time of every ok run per level (the costs the design divides by)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(4.6, 3.6))
    ok = df[df["status"] == "ok"]
    for j, dx in enumerate(levels):
        c = ok.loc[np.isclose(ok["dx"].astype(float), dx), "cpu_time_s"].astype(float)
        ax.plot(np.full(len(c), j) + np.linspace(-0.15, 0.15, max(len(c), 1))[:len(c)], c, "o",
                ms=3, alpha=0.6, color=f"C{j}")
        if len(c):
            ax.plot([j - 0.25, j + 0.25], [np.median(c)] * 2, "k-", lw=1.5)
            ax.annotate(f"{np.median(c):.1f} s", (j + 0.27, np.median(c)), fontsize=7,
                        va="center")
    ax.set_xticks(range(len(levels)), [f"dx {dx:g}" for dx in levels])
    ax.set_yscale("log")
    ax.set_ylabel("CPU seconds per run (median: line)")
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
