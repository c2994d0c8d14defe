// The study page's application (tools/dss/html_report.py inlines it after Plotly's bundle and
// the page's JSON data block). Plotly draws every figure; this file only lays out the page,
// evaluates the emulator from the exported fitted data and wires the controls.
"use strict";
(function () {
  const statusEl = document.getElementById("page-status");
  const app = document.getElementById("app");

  function fail(msg) {
    statusEl.dataset.status = "error";
    statusEl.textContent = "This page's data is broken: " + msg;
    console.error("mixsph report: " + msg);
    throw new Error(msg);
  }

  let D;
  try {
    D = JSON.parse(document.getElementById("page-data").textContent);
  } catch (e) {
    fail("cannot read the data block: " + e.message);
  }
  if (!D || typeof D !== "object" || !D.kind) fail("the data block has no kind");

  // ---- small helpers --------------------------------------------------------------------------
  function el(tag, attrs, ...kids) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "text") e.textContent = v;
      else if (k === "html") e.innerHTML = v;
      else e.setAttribute(k, v);
    }
    for (const k of kids) if (k != null) e.append(k);
    return e;
  }
  function section(id, title, caption) {
    const s = el("section", { id: id }, el("h2", { text: title }));
    if (caption) s.append(el("p", { class: "caption", text: caption }));
    app.append(s);
    return s;
  }
  function fmt(v, digits) {
    if (v === null || v === undefined || (typeof v === "number" && !isFinite(v))) return "n/a";
    if (typeof v !== "number") return String(v);
    if (digits !== undefined) return v.toFixed(digits);
    const a = Math.abs(v);
    if (a !== 0 && (a < 1e-3 || a >= 1e6)) return v.toExponential(3);
    return String(Number(v.toPrecision(5)));
  }
  function table(columns, rows, attrs) {
    const t = el("table", attrs || {});
    t.append(el("thead", {}, el("tr", {}, ...columns.map((c) => el("th", { text: c })))));
    const tb = el("tbody");
    for (const r of rows) tb.append(el("tr", {}, ...r.map((v) => el("td", { text: fmt(v) }))));
    t.append(tb);
    return t;
  }
  function kv(pairs) {
    return table(["", ""], pairs.filter((p) => p[1] !== undefined && p[1] !== null), { class: "kv" });
  }
  const PLOT_CFG = { displaylogo: false, responsive: true };
  // the standard normal upper tail, for the scenario's chance of exceeding the crest (display:
  // Abramowitz & Stegun 7.1.26, |error| < 1.5e-7)
  function normSf(z) {
    const x = Math.abs(z) / Math.SQRT2;
    const t = 1 / (1 + 0.3275911 * x);
    const e = t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429)))) * Math.exp(-x * x);
    return z >= 0 ? 0.5 * e : 1 - 0.5 * e;
  }

  // ---- the emulator, evaluated from its exported fitted data ------------------------------------
  function f64(s, n, what) {
    let bin;
    try {
      bin = atob(s);
    } catch (e) {
      fail(what + ": not base64");
    }
    if (bin.length % 8) fail(what + ": not a whole number of float64 values");
    const u = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) u[i] = bin.charCodeAt(i);
    const a = new Float64Array(u.buffer);
    if (a.length !== n) fail(`${what}: ${a.length} numbers, expected ${n}`);
    for (let i = 0; i < a.length; i++) if (!isFinite(a[i])) fail(`${what}: value ${i} is not finite`);
    return a;
  }
  function prepareGP(g, what) {
    if (!(g.n > 0 && g.d > 0)) fail(`${what}: no training runs`);
    if (!Array.isArray(g.factors) || !g.factors.length) fail(`${what}: no kernel factors`);
    for (const f of g.factors) {
      if (f.type !== "matern52" && f.type !== "rbf") fail(`${what}: unknown kernel factor ${f.type}`);
      if (!Array.isArray(f.ls) || f.ls.length !== g.d || !f.ls.every((v) => v > 0)) fail(`${what}: length scales`);
    }
    if (!(g.c > 0) || !(g.std > 0) || !isFinite(g.mean)) fail(`${what}: constant, mean or sd`);
    if (g.noise !== null && g.noise !== undefined && !(g.noise >= 0)) fail(`${what}: noise`);
    const L = f64(g.L, (g.n * (g.n + 1)) / 2, what + " L");
    for (let i = 0, off = 0; i < g.n; off += ++i) if (!(L[off + i] > 0)) fail(`${what}: L is not a Cholesky factor`);
    return {
      n: g.n, d: g.d, c: g.c, factors: g.factors, mean: g.mean, std: g.std, noise: g.noise || 0, L: L,
      X: f64(g.X, g.n * g.d, what + " X"), alpha: f64(g.alpha, g.n, what + " alpha"),
      ks: new Float64Array(g.n), w: new Float64Array(g.n),
    };
  }
  // latent mean and variance of one GP at inputs u (its own columns of the unit box), and its
  // own noise variance: the kernel c times Matern 5/2 and RBF factors (scikit-learn's), the
  // weights alpha and the Cholesky factor L of the fitted GP (multifidelity.DeltaGP.predict)
  function gpPredict(g, u) {
    const n = g.n, d = g.d, X = g.X, ks = g.ks, w = g.w, L = g.L;
    let m = 0;
    for (let i = 0; i < n; i++) {
      let k = g.c;
      for (const f of g.factors) {
        let r2 = 0;
        for (let j = 0; j < d; j++) {
          const t = (u[j] - X[i * d + j]) / f.ls[j];
          r2 += t * t;
        }
        if (f.type === "rbf") k *= Math.exp(-0.5 * r2);
        else {
          const r = Math.sqrt(r2) * Math.sqrt(5);
          k *= (1 + r + (r * r) / 3) * Math.exp(-r);
        }
      }
      ks[i] = k;
      m += k * g.alpha[i];
    }
    let q = 0;
    for (let i = 0, off = 0; i < n; off += ++i) {
      let s = ks[i];
      for (let j = 0; j < i; j++) s -= L[off + j] * w[j];
      w[i] = s / L[off + i];
      q += w[i] * w[i];
    }
    return [m * g.std + g.mean, Math.max(g.c - q, 0) * g.std * g.std, g.noise * g.std * g.std];
  }

  let EM = null;
  function prepareEmulator(e) {
    if (!e || (e.kind !== "mf" && e.kind !== "sf")) fail("no emulator in the data");
    const out = { kind: e.kind, inputs: e.inputs, levels: e.levels, outputs: {} };
    for (const [name, o] of Object.entries(e.outputs || {})) {
      const gps = o.gps.map((g, k) => prepareGP(g, `${name} GP ${k}`));
      for (const [key, f] of Object.entries(o.forms)) {
        if (!Array.isArray(f.coef) || f.coef.length > gps.length || !f.coef.every(isFinite)) fail(`${name} ${key}: coefficients`);
        if (f.order && f.order.length !== f.coef.length) fail(`${name} ${key}: order coefficients`);
        if (!(f.noise === null || f.noise >= 0) || !(f.scale > 0)) fail(`${name} ${key}: noise or scale`);
        if (f.route && !Object.values(f.route.parts).every((i) => gps[i])) fail(`${name} ${key}: routes`);
      }
      out.outputs[name] = { gps: gps, forms: o.forms, raw: o };
    }
    if (!Object.keys(out.outputs).length) fail("the emulator has no output");
    return out;
  }
  // the prediction at a level: the linear form of the GPs that Python's
  // OutputMF.linear_form gives (multifidelity.OutputMF.predict_form); for a single-fidelity
  // emulator one GP (the one of the binary inputs' level in mode separate) with its own noise
  function predict(output, level, x) {
    const o = EM.outputs[output];
    if (!o) throw new Error("no output " + output);
    const f = o.forms[level];
    if (!f) throw new Error("no level " + level);
    let u = EM.inputs.map((inp, j) => (x[j] - inp.lo) / (inp.hi - inp.lo));
    let gps = o.gps;
    if (f.route) {
      const key = f.route.bin.map((j) => Math.round(Math.min(1, Math.max(0, u[j])))).join(",");
      if (!(key in f.route.parts)) return { mean: NaN, sd: NaN };
      gps = [o.gps[f.route.parts[key]]];
      u = f.route.cont.map((j) => u[j]);
    }
    let mean = 0, v = 0, om = 0, own = 0;
    for (let k = 0; k < f.coef.length; k++) {
      const [m, vk, nk] = gpPredict(gps[k], u);
      mean += f.coef[k] * m;
      v += f.coef[k] * f.coef[k] * vk;
      own += f.coef[k] * f.coef[k] * nk;
      if (f.order) om += f.order[k] * m;
    }
    const vt = (v + (f.noise === null ? own : f.noise)) * f.scale * f.scale + (f.order ? om * om : 0);
    return { mean: mean, sd: Math.sqrt(vt) };
  }
  // the page's self-check: Python's predictions at a few points, recomputed here
  function selfCheck(checks) {
    for (const c of checks || []) {
      const p = predict(c.output, c.level, c.x);
      const tol = 1e-9 * Math.max(1, Math.abs(c.mean));
      if (!(Math.abs(p.mean - c.mean) <= tol && Math.abs(p.sd - c.sd) <= tol))
        fail(`the emulator here gives ${p.mean} +- ${p.sd} for ${c.output} at ${c.level} where Python gave ${c.mean} +- ${c.sd}`);
    }
  }

  // ---- the runs table and one run's plots ----------------------------------------------------
  function runsSection(runs, caption) {
    const s = section("runs", "The simulated runs", caption);
    if (!runs || !runs.rows.length) {
      s.append(el("p", { text: "No runs in this folder." }));
      return;
    }
    const cols = runs.columns;
    const t = el("table", { id: "runs-table", class: "runs" });
    const hr = el("tr");
    cols.forEach((c, j) => {
      const th = el("th", { text: c, title: "sort by " + c, "data-col": String(j) });
      th.addEventListener("click", () => sortBy(j));
      hr.append(th);
    });
    t.append(el("thead", {}, hr));
    const tb = el("tbody");
    runs.rows.forEach((r, i) => {
      const tr = el("tr", { "data-run": String(i) }, ...r.map((v) => el("td", { text: fmt(v) })));
      tr.addEventListener("click", () => showRun(i));
      tb.append(tr);
    });
    t.append(tb);
    const wrap = el("div", { class: "scroll" }, t);
    s.append(el("p", { class: "hint", text: `${runs.rows.length} runs; click a column to sort, a row to see the run.` }), wrap);
    const anims = D.animations || {};
    const title = el("h3", { id: "run-title", text: "" });
    const plot = el("div", { id: "run-plot", class: "plot" });
    const animBox = el("div", { id: "run-animation" });
    const runNote = el("p", { class: "hint" });
    const animIds = Object.keys(anims).filter((k) => k !== "_note");
    s.append(el("p", { class: "hint", text: animIds.length
      ? `The runs marked * (${animIds.length}: the lowest, median and highest run-up at the finest dx) were replayed with mixsph for their particles: click one to animate it.`
      : "No run was replayed for its particles" + (anims._note ? ": " + anims._note : " (python -m tools.dss page DIR --animate N replays N runs).") }));
    s.append(title, runNote, plot, animBox);
    runs.rows.forEach((r, i) => { if (anims[r[0]]) tb.children[i].children[0].textContent = r[0] + " *"; });
    let dir = {};
    function sortBy(j) {
      dir[j] = -(dir[j] || -1);
      const trs = Array.from(tb.children);
      trs.sort((a, b) => {
        const va = runs.rows[+a.dataset.run][j], vb = runs.rows[+b.dataset.run][j];
        if (va === vb) return 0;
        if (va === null || va === "") return 1;
        if (vb === null || vb === "") return -1;
        return (va < vb ? -1 : 1) * dir[j];
      });
      tb.append(...trs);
    }
    function showRun(i) {
      for (const tr of tb.children) tr.classList.toggle("selected", +tr.dataset.run === i);
      const ser = runs.series[i];
      const id = runs.rows[i][0];
      title.textContent = "Run " + id;
      const oldAnim = document.getElementById("animation");
      if (oldAnim) Plotly.purge(oldAnim);
      animBox.textContent = "";
      const an = anims[id];
      if (an) {
        const yj = runs.columns.indexOf("max_run_up");
        animation(animBox, an.frames, `Replayed with mixsph (${an.path}): its max run-up ${fmt(an.max_run_up)} m, the FMU run's ${fmt(yj >= 0 ? runs.rows[i][yj] : null)} m (the same library and scenario; the monitors' sampling may differ).`);
      }
      if (!ser || !ser.time) {
        Plotly.purge(plot);
        runNote.textContent = "This run recorded no monitors over time.";
        return;
      }
      runNote.textContent = "";
      const names = Object.keys(ser).filter((k) => k !== "time");
      const traces = names.map((k, j) => ({
        x: ser.time, y: ser[k], name: k, mode: "lines", xaxis: "x", yaxis: j ? "y" + (j + 1) : "y",
      }));
      const layout = { height: 170 * names.length + 60, margin: { t: 30, l: 70, r: 20, b: 40 },
        grid: { rows: names.length, columns: 1, shared_xaxes: true, pattern: "independent" },
        showlegend: false, title: { text: "monitors over time of run " + id, font: { size: 13 } } };
      names.forEach((k, j) => {
        layout["yaxis" + (j ? j + 1 : "")] = { title: { text: k, font: { size: 11 } } };
        layout["xaxis" + (j ? j + 1 : "")] = { title: j === names.length - 1 ? { text: "t [s]" } : undefined, matches: j ? "x" : undefined };
      });
      Plotly.react(plot, traces.map((tr, j) => ({ ...tr, xaxis: "x" + (j ? j + 1 : ""), yaxis: "y" + (j ? j + 1 : "") })), layout, PLOT_CFG);
    }
    showRun(0);
  }

  function animation(target, frames, caption) {
    if (!frames || !frames.length) {
      target.append(el("p", { text: "No particle snapshots in this run's folder." }));
      return;
    }
    const div = el("div", { id: "animation", class: "plot" });
    target.append(div);
    if (caption) target.append(el("p", { class: "caption", text: caption }));
    const colour = (c) => c.map((m) => (m < 0 ? "#888888" : m === 0 ? "#1f77b4" : m === 1 ? "#b5651d" : "#2ca02c"));
    let xmin = Infinity, xmax = -Infinity, zmin = Infinity, zmax = -Infinity;
    for (const f of frames) {
      for (const v of f.x) if (v !== null) { xmin = Math.min(xmin, v); xmax = Math.max(xmax, v); }
      for (const v of f.z) if (v !== null) { zmin = Math.min(zmin, v); zmax = Math.max(zmax, v); }
    }
    const tr = (f) => ({ x: f.x, y: f.z, mode: "markers", type: "scattergl", marker: { size: 3, color: colour(f.c) } });
    const steps = frames.map((f, i) => ({ label: fmt(f.t), method: "animate", args: [["f" + i], { mode: "immediate", frame: { duration: 0, redraw: true }, transition: { duration: 0 } }] }));
    Plotly.newPlot(div, [tr(frames[0])], {
      height: 420, margin: { t: 30, l: 60, r: 20, b: 40 },
      xaxis: { range: [xmin, xmax], title: { text: "x [m]" } },
      yaxis: { range: [zmin, zmax], title: { text: "z [m]" }, scaleanchor: "x" },
      title: { text: "particles coloured by medium (0 blue, 1 brown, 2 green; walls grey)", font: { size: 13 } },
      updatemenus: [{ type: "buttons", showactive: false, x: 0, y: -0.15, xanchor: "left", buttons: [
        { label: "play", method: "animate", args: [null, { frame: { duration: 150, redraw: true }, fromcurrent: true, transition: { duration: 0 } }] },
        { label: "pause", method: "animate", args: [[null], { mode: "immediate", frame: { duration: 0 } }] }] }],
      sliders: [{ x: 0.15, len: 0.85, y: -0.1, currentvalue: { prefix: "t = ", suffix: " s" }, steps: steps }],
    }, PLOT_CFG).then(() => Plotly.addFrames(div, frames.map((f, i) => ({ name: "f" + i, data: [tr(f)] }))));
  }

  // "start: 28 runs; 83 batches cost-aware (finest): 274 runs"
  function groupBatches(batches) {
    const g = [];
    for (const b of batches) {
      const last = g[g.length - 1];
      if (last && last.kind === b.kind) { last.k++; last.n += b.n; } else g.push({ kind: b.kind, k: 1, n: b.n });
    }
    return g.map((x) => (x.k > 1 ? `${x.k} batches ${x.kind}: ${x.n} runs` : `${x.kind}: ${x.n} runs`)).join("; ");
  }

  // ---- versions and settings -----------------------------------------------------------------
  function versionPairs(v) {
    v = v || {};
    const lib = v.libraries || {};
    return [
      ["mixsph (this checkout)", [v.mixsph, v.commit].filter(Boolean).join(", ") || undefined],
      ["FMU model version", v.fmu_version], ["FMU GUID", v.fmu_guid],
      ["FMU SHA-256", v.fmu_sha256], ["FMU file", v.fmu_path], ["FMU note", v.fmu_note],
      ["emulator file made", v.emulator_file],
      ["emulator fitted with", v.emulator_libraries ? Object.entries(v.emulator_libraries).map(([k, x]) => k + " " + x).join(", ") : undefined],
      ["page made with", Object.entries(lib).map(([k, x]) => k + " " + x).join(", ")],
    ];
  }

  // the prediction panel, the one-input sweeps and the two-input maps, all from predict():
  // P = {riskOut, R: {crest, output, level}, inputs, sobol, caption}
  function predictionPanel(P) {
    const outputs = Object.keys(EM.outputs);
    const riskOut = P.riskOut;
    const R = P.R || {};
    const crest = R.crest === null ? undefined : R.crest;
    // the prediction panel
    const ps = section("predict", "Predict a scenario", P.caption);
    const ctrl = el("div", { class: "controls" });
    const lvSel = el("select", { id: "level" }, ...EM.levels.map((l) => el("option", { value: l.key, text: l.label })));
    const outSel = el("select", { id: "output" }, ...outputs.map((o) => el("option", { value: o, text: o })));
    outSel.value = riskOut;
    lvSel.value = EM.levels.some((l) => l.key === String(R.level)) ? String(R.level) : EM.levels[0].key;
    ctrl.append(el("label", {}, "level ", lvSel), el("label", {}, "output ", outSel));
    const sliders = [];
    const inputs = P.inputs || EM.inputs;
    inputs.forEach((inp, j) => {
      const ch = inp.choices && inp.choices.length ? inp.choices.slice().sort((a, b) => a - b) : null;
      let step = (inp.hi - inp.lo) / 200;
      if (ch && ch.length > 1) step = Math.min(...ch.slice(1).map((v, i) => v - ch[i]));
      const mid = ch ? ch[Math.floor((ch.length - 1) / 2)] : inp.lo + 0.5 * (inp.hi - inp.lo);
      const s = el("input", { type: "range", id: "slider-" + inp.name, min: String(inp.lo), max: String(inp.hi), step: String(step), value: String(mid) });
      const val = el("span", { class: "value", id: "value-" + inp.name });
      sliders.push(s);
      ctrl.append(el("label", { class: "slider" }, el("span", { class: "name", text: inp.name }), s, val,
        el("span", { class: "range", text: `${fmt(inp.lo)} to ${fmt(inp.hi)}${inp.dist ? " (" + inp.dist + ")" : ""}` })));
    });
    const res = el("div", { class: "result" },
      el("div", {}, "run-up ", el("span", { id: "pred-mean", class: "big" }), " ", el("span", { id: "pred-unit" })),
      el("div", {}, "95 % interval ", el("span", { id: "pred-lo" }), " to ", el("span", { id: "pred-hi" }), ", sd ", el("span", { id: "pred-sd" })),
      el("div", { id: "pred-exceed" }));
    ps.append(ctrl, res);

    const sw = section("sweeps", "How the run-up responds",
      "Each panel varies one input across the study's box with the others at the sliders' values: the line is the emulator's mean, the band its 95 % interval for a new run; the dashed line is the crest. " +
      "The contour maps vary two inputs at once. Where the band is wide the study's runs say little: more runs there would narrow it.");
    const sweepDiv = el("div", { id: "sweep-plot", class: "plot" });
    const axX = el("select", { id: "surf-x" }, ...EM.inputs.map((i) => el("option", { value: i.name, text: i.name })));
    const axY = el("select", { id: "surf-y" }, ...EM.inputs.map((i) => el("option", { value: i.name, text: i.name })));
    const S = P.sobol || {};
    let rank = EM.inputs.map((i) => i.name);
    if (S.names && S.ST) rank = S.names.slice().sort((a, b) => S.ST[S.names.indexOf(b)] - S.ST[S.names.indexOf(a)]);
    axX.value = rank[0];
    axY.value = rank[1] || rank[0];
    const surfDiv = el("div", { id: "surface-plot", class: "plot" });
    const surfNote = el("p", { class: "hint" });
    sw.append(sweepDiv, el("div", { class: "controls" }, el("label", {}, "map x ", axX), el("label", {}, "map y ", axY)), surfNote, surfDiv);

    function current() {
      return sliders.map((s, j) => {
        const inp = inputs[j];
        let v = parseFloat(s.value);
        if (inp.choices && inp.choices.length) v = inp.choices.reduce((a, b) => (Math.abs(b - v) < Math.abs(a - v) ? b : a));
        return v;
      });
    }
    function update() {
      const x = current();
      const out = outSel.value, lv = lvSel.value;
      sliders.forEach((s, j) => (document.getElementById("value-" + inputs[j].name).textContent = fmt(x[j])));
      const p = predict(out, lv, x);
      const lo = p.mean - 1.959963984540054 * p.sd, hi = p.mean + 1.959963984540054 * p.sd;
      const set = (id, v) => {
        const e = document.getElementById(id);
        e.textContent = fmt(v, 4);
        e.dataset.value = String(v);
      };
      set("pred-mean", p.mean);
      set("pred-lo", lo);
      set("pred-hi", hi);
      set("pred-sd", p.sd);
      document.getElementById("pred-unit").textContent = out.endsWith("_Z") ? "m a.m.s.l." : "m (model scale)";
      const ex = document.getElementById("pred-exceed");
      if (crest !== undefined && out === R.output) {
        const pe = normSf((crest - p.mean) / p.sd);
        ex.textContent = `chance that one run of this scenario exceeds the crest ${fmt(crest)}: ${(100 * pe).toFixed(1)} %`;
      } else ex.textContent = "";
      drawSweeps(out, lv, x);
      drawSurface(out, lv, x);
    }
    function drawSweeps(out, lv, x) {
      const n = EM.inputs.length, npts = 41;
      const traces = [], layout = { height: 260, margin: { t: 30, l: 60, r: 10, b: 50 }, showlegend: false,
        grid: { rows: 1, columns: n, pattern: "independent" } };
      EM.inputs.forEach((inp, j) => {
        // a choice input (saturated 0/1) only at its values; a continuous one over its box
        const ch = (inputs[j].choices || []).slice().sort((a, b) => a - b);
        const vals = ch.length ? ch : Array.from({ length: npts }, (_, k) => inp.lo + ((inp.hi - inp.lo) * k) / (npts - 1));
        const xs = [], m = [], lo = [], hi = [], half = [];
        for (const v of vals) {
          const xx = x.slice();
          xx[j] = v;
          const p = predict(out, lv, xx);
          xs.push(v); m.push(p.mean); half.push(1.959963984540054 * p.sd);
          lo.push(p.mean - 1.959963984540054 * p.sd); hi.push(p.mean + 1.959963984540054 * p.sd);
        }
        const ax = j ? String(j + 1) : "";
        if (ch.length) {
          traces.push({ x: xs, y: m, mode: "markers", marker: { color: "#1f77b4", size: 9 }, error_y: { type: "data", array: half }, xaxis: "x" + ax, yaxis: "y" + ax, name: out });
        } else {
          traces.push({ x: xs, y: hi, mode: "lines", line: { width: 0 }, xaxis: "x" + ax, yaxis: "y" + ax, hoverinfo: "skip" });
          traces.push({ x: xs, y: lo, mode: "lines", line: { width: 0 }, fill: "tonexty", fillcolor: "rgba(31,119,180,0.2)", xaxis: "x" + ax, yaxis: "y" + ax, name: "95 %" });
          traces.push({ x: xs, y: m, mode: "lines", line: { color: "#1f77b4" }, xaxis: "x" + ax, yaxis: "y" + ax, name: out });
        }
        traces.push({ x: [x[j]], y: [predict(out, lv, x).mean], mode: "markers", marker: { color: "#d62728", size: 8 }, xaxis: "x" + ax, yaxis: "y" + ax, name: "sliders" });
        if (crest !== undefined && out === R.output)
          traces.push({ x: [inp.lo, inp.hi], y: [crest, crest], mode: "lines", line: { color: "black", dash: "dash", width: 1 }, xaxis: "x" + ax, yaxis: "y" + ax, name: "crest" });
        layout["xaxis" + ax] = { title: { text: inp.name }, ...(ch.length ? { tickvals: ch, range: [ch[0] - 0.3 * (ch[ch.length - 1] - ch[0] || 1), ch[ch.length - 1] + 0.3 * (ch[ch.length - 1] - ch[0] || 1)] } : {}) };
        layout["yaxis" + ax] = { title: j ? undefined : { text: out } };
      });
      Plotly.react(sweepDiv, traces, layout, PLOT_CFG);
    }
    function drawSurface(out, lv, x) {
      const jx = EM.inputs.findIndex((i) => i.name === axX.value), jy = EM.inputs.findIndex((i) => i.name === axY.value);
      if (jx === jy) {
        Plotly.purge(surfDiv);
        surfNote.textContent = "Pick two different inputs for the map.";
        return;
      }
      surfNote.textContent = "";
      const ix = EM.inputs[jx], iy = EM.inputs[jy], npts = 31;
      const xs = [], ys = [], zm = [], zh = [];
      for (let a = 0; a < npts; a++) xs.push(ix.lo + ((ix.hi - ix.lo) * a) / (npts - 1));
      for (let b = 0; b < npts; b++) ys.push(iy.lo + ((iy.hi - iy.lo) * b) / (npts - 1));
      for (let b = 0; b < npts; b++) {
        const rm = [], rh = [];
        for (let a = 0; a < npts; a++) {
          const xx = x.slice();
          xx[jx] = xs[a];
          xx[jy] = ys[b];
          const p = predict(out, lv, xx);
          rm.push(p.mean);
          rh.push(1.959963984540054 * p.sd);
        }
        zm.push(rm);
        zh.push(rh);
      }
      const traces = [
        { type: "contour", x: xs, y: ys, z: zm, colorscale: "Viridis", colorbar: { x: 0.4, len: 0.9, thickness: 14, title: { text: out, side: "right" } }, contours: { showlabels: true }, xaxis: "x", yaxis: "y", name: "mean" },
        { type: "contour", x: xs, y: ys, z: zh, colorscale: "Reds", colorbar: { x: 0.97, len: 0.9, thickness: 14, title: { text: "95 % half-width", side: "right" } }, xaxis: "x2", yaxis: "y2", name: "95 % half-width" },
        { x: [x[jx]], y: [x[jy]], mode: "markers", marker: { color: "white", size: 9, line: { color: "black", width: 1 } }, xaxis: "x", yaxis: "y", name: "sliders", showlegend: false },
      ];
      if (crest !== undefined && out === R.output)
        traces.push({ type: "contour", x: xs, y: ys, z: zm, showscale: false, contours: { start: crest, end: crest, size: 1, coloring: "none", showlabels: true }, line: { color: "red", width: 2, dash: "dash" }, xaxis: "x", yaxis: "y", name: "crest", hoverinfo: "skip" });
      Plotly.react(surfDiv, traces, {
        height: 380, margin: { t: 40, l: 60, r: 40, b: 50 },
        xaxis: { title: { text: ix.name }, domain: [0, 0.34] }, yaxis: { title: { text: iy.name } },
        xaxis2: { title: { text: ix.name }, domain: [0.55, 0.89] }, yaxis2: { title: { text: iy.name }, anchor: "x2" },
        title: { text: `mean (left, crest dashed red) and 95 % half-width (right) at ${lvSel.options[lvSel.selectedIndex].text}`, font: { size: 13 } },
      }, PLOT_CFG);
    }
    for (const e of [...sliders, lvSel, outSel, axX, axY]) e.addEventListener("input", update);
    update();
  }

  // ---- the study page ------------------------------------------------------------------------
  function studyPage() {
    EM = prepareEmulator(D.emulator);
    selfCheck(D.checks);
    const outputs = Object.keys(EM.outputs);
    const riskOut = D.risk_output && EM.outputs[D.risk_output] ? D.risk_output : outputs[0];
    const R = D.risk || {};
    const crest = R.crest;
    const disc = D.discretisation;

    // the answer, first
    const head = section("answer", "The answer");
    if (R.p !== undefined) {
      head.append(el("p", { class: "answer", id: "answer-p", text:
        `P(${R.output} > ${fmt(crest)}) = ${fmt(R.p, 3)} (95 % band ${fmt(R.p_lo, 3)} to ${fmt(R.p_hi, 3)}) at the level ${R.level}, over the study's input distributions.` }));
    }
    head.append(el("p", { class: "caption", text:
      "The band is the emulator's uncertainty (and, at the extrapolated level, that of the order of convergence), from joint posterior draws; " +
      (disc ? `the study's finest runs are at dx = ${fmt(disc.finest_dx)} m, and over the box they differ from the extrapolated dx -> 0 value by ${fmt(disc.mean_abs)} m on average (largest ${fmt(disc.max_abs)} m), with an observed order of convergence ${fmt(disc.order.p)} (95 % of the box ${fmt(disc.order.p_lo)}-${fmt(disc.order.p_hi)}). ` : "") +
      "It does not hold the distance of a coarse ladder from the asymptotic range, nor the model's own error against the experiment (docs/validation/vajont.md)." }));

    predictionPanel({ riskOut: riskOut, R: R, inputs: D.inputs, sobol: D.sobol, caption:
      "Move a slider: the emulator is evaluated in this page from its fitted data (the same numbers Python predicts with, to 1e-9). " +
      "The interval is for one new FMU run at that level (95 %); outside the study's box the emulator extrapolates and the sliders stop at the box." });
    const S = D.sobol || {};

    // exceedance
    if (R.curve) {
      const es = section("exceedance", "How likely is overtopping",
        `The chance that the run-up (${R.output}) exceeds a level z when the inputs follow the study's distributions (${(D.inputs || []).map((i) => i.name + " " + (i.dist || "")).join(", ")}), at the level ${R.level}. ` +
        `The band is the emulator's uncertainty (${R.n_draws} joint draws at ${R.n_joint} scenarios); the Monte Carlo error of the ${R.n} samples is ${fmt(R.mc_se)}. ` +
        "The dashed grey curve uses the emulator's mean alone (no uncertainty): the gap between the two is what the emulator's uncertainty adds.");
      const div = el("div", { id: "exceedance-plot", class: "plot" });
      es.append(div);
      const c = R.curve;
      Plotly.newPlot(div, [
        { x: c.z, y: c.hi, mode: "lines", line: { width: 0 }, showlegend: false, hoverinfo: "skip" },
        { x: c.z, y: c.lo, mode: "lines", line: { width: 0 }, fill: "tonexty", fillcolor: "rgba(31,119,180,0.25)", name: "95 % band" },
        { x: c.z, y: c.p, mode: "lines", line: { color: "#1f77b4" }, name: "P(run-up > z)" },
        { x: c.z, y: c.mean_only, mode: "lines", line: { color: "grey", dash: "dash" }, name: "from the mean alone" },
        { x: [crest, crest], y: [0, 1], mode: "lines", line: { color: "black", dash: "dot" }, name: `crest ${fmt(crest)}` },
      ], { height: 360, margin: { t: 40, l: 60, r: 20, b: 50 }, xaxis: { title: { text: R.output } }, yaxis: { title: { text: "exceedance probability" }, range: [0, 1.02] },
        title: { text: `P(> ${fmt(crest)}) = ${fmt(R.p, 3)} [${fmt(R.p_lo, 3)}, ${fmt(R.p_hi, 3)}]`, font: { size: 13 } } }, PLOT_CFG);
    }

    // Sobol indices
    if (S.names) {
      const ss = section("sobol", "What drives it",
        `Sobol indices of the emulator's mean of ${R.output || riskOut} at the level ${S.level}: the share of the run-up's variance over the input distributions that each input explains alone (first order) and with its interactions (total), with 95 % bootstrap intervals (SALib, ${S.n_model} evaluations). ` +
        "An input with a total index near 0 could be fixed without changing the answer; the indices are of the mean and say nothing of the emulator's uncertainty.");
      const div = el("div", { id: "sobol-plot", class: "plot" });
      ss.append(div);
      Plotly.newPlot(div, [
        { type: "bar", x: S.names, y: S.S1, name: "first order", error_y: { type: "data", array: S.S1_conf } },
        { type: "bar", x: S.names, y: S.ST, name: "total", error_y: { type: "data", array: S.ST_conf } },
      ], { height: 320, margin: { t: 20, l: 60, r: 20, b: 60 }, barmode: "group", yaxis: { title: { text: "Sobol index" }, range: [0, 1.05] } }, PLOT_CFG);
    }

    // validation
    const vs = section("validation", "How sure: the emulator's validation",
      "Leave-one-out checks of each level (each run predicted from the others, hyperparameters fixed): the error and how many runs fall inside their 95 % intervals (about 95 % is calibrated; an interval scale above 1 was applied to widen intervals that were too narrow). " +
      "Hold-out checks (emulate mf-validate --json into the study folder) are listed when present: they are the independent test.");
    for (const [name, o] of Object.entries(EM.outputs)) {
      const cal = o.raw.calibration || [];
      vs.append(el("h3", { text: name }), table(["dx", "runs", "LOO RMSE", "rms z", "inside 95 %", "interval scale"],
        cal.map((c) => [c.dx, c.n, c.loo_rmse, c.loo_rms_z, (100 * c.loo_coverage95).toFixed(0) + " %", c.scale_applied])));
      const od = o.raw.order || {};
      if (od.p) vs.append(el("p", { text: `order of convergence ${fmt(od.p)} (95 % over the box ${fmt(od.p_lo)}-${fmt(od.p_hi)}; ${od.source || ""})` }));
    }
    if ((D.validation || []).length) {
      vs.append(el("h3", { text: "hold-out" }), table(["file", "level", "hold-out dx", "runs", "RMSE", "RMSE %", "largest %", "inside 95 %", "rms z"],
        D.validation.map((v) => [v.file, v.level, v.holdout_dx, v.metrics.n, v.metrics.rmse, v.metrics.rmse_pct, v.metrics.max_error_pct, (100 * v.metrics.coverage95).toFixed(0) + " %", v.rms_z])));
    } else vs.append(el("p", { text: "No hold-out check in this folder." }));

    // inputs of the study
    const is = section("inputs", "The study's inputs", "What was varied, over which range and distribution, at which particle spacings, what it cost, and the versions it ran with.");
    is.append(table(["input", "distribution", "box low", "box high"], (D.inputs || []).map((i) => [i.name, i.dist || "", i.lo, i.hi])));
    const st = D.settings || {}, dg = D.design || {}, spec = dg.spec || {};
    const cost = D.cost || {};
    is.append(el("h3", { text: "design and cost" }), kv([
      ["levels dx [m]", (st.levels || spec.levels || []).join(", ")],
      ["stop time [s]", st.stop_time], ["communication step [s]", st.step],
      ["fixed parameters", Object.entries(st.fixed || {}).map(([k, v]) => k + " = " + v).join(", ") || "none"],
      ["design", dg.batches ? groupBatches(dg.batches) : undefined],
      ["target of the design", spec.target], ["stopped", dg.stopped],
      ["CPU budget [s]", dg.budget_cpu_s], ["CPU spent [s]", cost.total_cpu_s],
      ["study's wall time [min]", D.elapsed_s ? D.elapsed_s / 60 : undefined],
    ]));
    is.append(table(["dx [m]", "runs", "median CPU s a run", "CPU s"], Object.entries(cost).filter(([k]) => k !== "total_cpu_s").map(([k, c]) => [k, c.runs, c.median_cpu_s, c.sum_cpu_s])));
    is.append(el("h3", { text: "versions" }), kv(versionPairs(D.versions)));

    runsSection(D.runs, "Every FMU run of the study, at every level. Clicking a run shows the monitors the FMU reported at each communication step. The FMU writes no particle files: a few runs are replayed with mixsph for theirs.");
  }

  // ---- the sweep page ------------------------------------------------------------------------
  function sweepPage() {
    const runs = D.runs;
    const is = section("inputs", "The sweep's inputs", "The parameters the scenarios vary, their range over the runs, and the run settings.");
    is.append(table(["parameter", "low", "high", "distinct values"], (D.inputs || []).map((i) => [i.name, i.lo, i.hi, i.values])));
    const st = D.settings || {};
    is.append(kv([["stop time [s]", st.stop_time], ["communication step [s]", st.step], ["dx [m]", st.dx],
      ["fixed parameters", Object.entries(st.fixed || {}).map(([k, v]) => k + " = " + v).join(", ") || "none"]]));
    is.append(el("h3", { text: "versions" }), kv(versionPairs(D.versions)));
    if (D.emulator) {
      // an emulator fitted on these runs (emulate fit / design): its panel and its CV
      EM = prepareEmulator(D.emulator);
      selfCheck(D.checks);
      const outs = Object.keys(EM.outputs);
      predictionPanel({ riskOut: outs.includes(D.y) ? D.y : outs[0], R: { crest: D.crest, output: D.y, level: "sf" },
        inputs: D.emulator_inputs, caption:
        `Move a slider: the emulator of these runs (emulator.json, made ${D.emulator_created || "?"}) is evaluated in this page from its fitted data (the same numbers Python predicts with, to 1e-9). ` +
        "The interval is for one new FMU run at the runs' dx (95 %); a binary input (saturated) takes 0 or 1; the sliders stop at the emulator's box." });
      const vs = section("validation", "How sure: the emulator's cross-validation",
        "k-fold cross-validation on the runs (each fold's runs predicted by an emulator fitted without them): the error, in % of the output's range over the runs, and how many runs fall inside their 95 % intervals (about 95 % is calibrated).");
      vs.append(table(["output", "mode", "runs", "folds", "RMSE", "RMSE %", "largest %", "inside 95 %"],
        Object.entries(EM.outputs).map(([n, o]) => { const c = o.raw.cv || {}; return [n, o.raw.mode, c.n, c.folds, c.rmse, c.rmse_pct, c.max_error_pct, c.coverage95 === undefined || c.coverage95 === null ? null : (100 * c.coverage95).toFixed(0) + " %"]; })));
    }
    const yj = runs.columns.indexOf(D.y), sj = runs.columns.indexOf("status");
    const ok = runs.rows.filter((r) => sj < 0 || r[sj] === "ok");
    if (yj >= 0 && ok.length) {
      const inputs = (D.inputs || []).map((i) => i.name);
      const xName = inputs.includes("reservoir_level") ? "reservoir_level" : inputs[0];
      const xj = runs.columns.indexOf(xName);
      const ys = ok.map((r) => r[yj]).filter((v) => v !== null).sort((a, b) => a - b);
      const rs = section("response", "Run-up over the scenarios",
        `Each point is one FMU run. The exceedance curve counts the runs above each level, every run weighing the same (over the sampled distributions, or over the grid's points): with ${ys.length} runs it resolves probabilities in steps of ${fmt(1 / ys.length)}.` +
        (D.crest !== null && D.crest !== undefined ? ` ${ys.filter((v) => v > D.crest).length} of ${ys.length} runs exceed ${fmt(D.crest)}.` : ""));
      if (xj >= 0) {
        const div = el("div", { id: "scatter-plot", class: "plot" });
        rs.append(div);
        Plotly.newPlot(div, [{ x: ok.map((r) => r[xj]), y: ok.map((r) => r[yj]), mode: "markers", type: "scatter", text: ok.map((r) => r[0]), name: "runs" }],
          { height: 340, margin: { t: 20, l: 70, r: 20, b: 50 }, xaxis: { title: { text: xName } }, yaxis: { title: { text: D.y } } }, PLOT_CFG);
      }
      const div2 = el("div", { id: "exceedance-plot", class: "plot" });
      rs.append(div2);
      const n = ys.length;
      // P(run-up > z): 1 below the smallest run, (n - 1 - i) / n from the i-th on
      const pad = 0.02 * (ys[n - 1] - ys[0] || 1);
      const tr = [{ x: [ys[0] - pad, ...ys], y: [1, ...ys.map((_, i) => (n - 1 - i) / n)], mode: "lines", line: { shape: "hv" }, name: "P(run-up > z)" }];
      if (D.crest !== null && D.crest !== undefined) tr.push({ x: [D.crest, D.crest], y: [0, 1], mode: "lines", line: { color: "black", dash: "dot" }, name: "crest" });
      Plotly.newPlot(div2, tr, { height: 320, margin: { t: 20, l: 70, r: 20, b: 50 }, xaxis: { title: { text: D.y } }, yaxis: { title: { text: "exceedance probability" }, range: [0, 1.02] } }, PLOT_CFG);
    }
    runsSection(runs, "Every scenario of the sweep with its status. Clicking a run shows the monitors the FMU reported at each communication step (runs made before the sweeps recorded them have none).");
  }

  // ---- the run page --------------------------------------------------------------------------
  function runPage() {
    const r = D.run;
    const sm = r.summary || {};
    const s = section("summary", "The run", "Status, counts and timings from summary.json, and the extremes of every monitor.");
    s.append(kv(Object.entries(sm).filter(([, v]) => typeof v !== "object").map(([k, v]) => [k, v])));
    if (sm.outputs) s.append(table(["output", "final", "max", "t of max", "min", "t of min"],
      Object.entries(sm.outputs).map(([k, o]) => [k, o.final, o.max, o.t_max, o.min, o.t_min])));
    s.append(el("h3", { text: "versions" }), kv(versionPairs(D.versions)));
    const mon = r.monitors || {};
    const names = Object.keys(mon).filter((k) => k !== "t" && k !== "step");
    const ms = section("monitors", "Monitors over time", "A monitor from monitors.csv against time (pick it); gaps are intervals where the monitor had no value (e.g. no particle in its window).");
    const sel = el("select", { id: "monitor" }, ...names.map((n) => el("option", { value: n, text: n })));
    if (names.includes("run_up")) sel.value = "run_up";
    const div = el("div", { id: "monitor-plot", class: "plot" });
    ms.append(el("div", { class: "controls" }, el("label", {}, "monitor ", sel)), div);
    const draw = () => Plotly.react(div, [{ x: mon.t, y: mon[sel.value], mode: "lines", name: sel.value }],
      { height: 320, margin: { t: 20, l: 70, r: 20, b: 50 }, xaxis: { title: { text: "t [s]" } }, yaxis: { title: { text: sel.value } } }, PLOT_CFG);
    sel.addEventListener("input", draw);
    if (names.length) draw();
    if ((r.profiles || []).length) {
      const ps = section("profiles", "Profiles", "The free surface and the landslide's surface (top of each medium per x bin) at the times the case asked for.");
      const pd = el("div", { id: "profile-plot", class: "plot" });
      ps.append(pd);
      Plotly.newPlot(pd, r.profiles.map((p) => ({ x: p.x, y: p.z, mode: "lines", name: `${p.name} t = ${fmt(p.t)} s`, connectgaps: false })),
        { height: 380, margin: { t: 20, l: 70, r: 20, b: 50 }, xaxis: { title: { text: "x [m]" } }, yaxis: { title: { text: "z [m]" } } }, PLOT_CFG);
    }
    const as = section("particles", "Particles", "The particle snapshots of the run, decimated (every k-th particle, at most 25 frames): play or drag the time slider.");
    animation(as, r.frames);
  }

  try {
    if (D.kind === "study") studyPage();
    else if (D.kind === "sweep") sweepPage();
    else if (D.kind === "run") runPage();
    else fail("unknown page kind " + D.kind);
  } catch (e) {
    if (statusEl.dataset.status !== "error") fail(e && e.message ? e.message : String(e));
    throw e;
  }
  window.mixsphReport = { predict: predict, data: D };
  statusEl.dataset.status = "ok";
  statusEl.textContent = "";
})();
