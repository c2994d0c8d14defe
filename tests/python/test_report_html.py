"""The study page (tools/dss/html_report.py, `python -m tools.dss page`) in a real browser:
Debian's chromium, headless, driven by Playwright for Python (the system browser; Playwright
downloads none).

The page of a small study (report_fixture: the multi-fidelity design of tools/dss on a stand-in
of the FMU, its fit and emulate study's ending) opens from disk with no JavaScript error, a
slider moved with the keyboard changes the prediction to what Python predicts at the sliders'
new values, and the page's emulator equals Python's (emulator.predict) at 20 random points at
every level and output to 1e-9; the check fails on a page whose data is broken (cut short, a
length scale changed, and the same without the page's own self-check). The sweep page sorts
its runs table and shows a run's monitors; the run page animates the particles.

Without a browser the tests skip, saying what to install; in CI (CI=true), where
./tools/do setup installs chromium, they fail instead.
"""

import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import report_fixture as RF  # noqa: E402
from tools.dss import html_report as H  # noqa: E402

ROOT = RF.ROOT
TOL = 1e-9


def _chromium():
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


def _need_browser():
    why = None
    path = _chromium()
    if path is None:
        why = "no chromium on PATH (Debian package chromium; ./tools/do setup installs it)"
    else:
        try:
            import playwright.sync_api  # noqa: F401
        except ImportError:
            why = "no Playwright for Python (pip package playwright, in tools/requirements.txt)"
    if why:
        if os.environ.get("CI", "").lower() in ("true", "1"):
            pytest.fail(f"the study page's browser test cannot run: {why}; CI=true, so this fails "
                        f"instead of skipping", pytrace=False)
        pytest.skip(f"the study page's browser test needs a browser: {why}")
    return path


@pytest.fixture(scope="module")
def browser():
    path = _need_browser()
    from playwright.sync_api import sync_playwright
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=path, headless=True)
        yield b
        b.close()


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("study"))
    em = RF.make_study(out)
    return out, em


def open_page(browser, path):
    """The page opened from disk, and the list its JavaScript errors go to."""
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    errors = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"uncaught: {e}"))
    page.goto("file://" + os.path.abspath(path))
    page.wait_for_function("document.getElementById('page-status').dataset.status !== 'loading'",
                           timeout=30_000)
    return page, errors


def assert_page_ok(page, errors):
    status = page.get_attribute("#page-status", "data-status")
    assert status == "ok", f"page status {status}: {page.inner_text('#page-status')}"
    assert not errors, f"JavaScript errors: {errors}"


def check_study_page(browser, path, em, screenshot=None, n_points=20, seed=5):
    """Everything the test asserts of a study page; raises AssertionError at the first failure."""
    page, errors = open_page(browser, path)
    try:
        assert_page_ok(page, errors)
        names = em.inputs

        def shown():
            x = [float(page.input_value(f"#slider-{n}")) for n in names]
            return x, page.input_value("#output"), page.input_value("#level"), \
                float(page.get_attribute("#pred-mean", "data-value")), \
                float(page.get_attribute("#pred-sd", "data-value"))
        x0, out, level, m0, _ = shown()
        # move the first slider to its end as a user would (keyboard on the focused slider)
        page.focus(f"#slider-{names[0]}")
        page.keyboard.press("End")
        x1, out1, level1, m1, s1 = shown()
        assert x1[0] == pytest.approx(em.box[0, 1]) and x1[1:] == x0[1:], (x0, x1)
        assert m1 != m0, "the prediction did not change when the slider moved"
        mu, sd = H.python_predict(em, out1, level1, np.array([x1]))
        assert abs(m1 - mu[0]) <= TOL and abs(s1 - sd[0]) <= TOL, \
            f"the page shows {m1} +- {s1} at the sliders {x1}, Python predicts {mu[0]} +- {sd[0]}"
        assert page.inner_text("#pred-mean") == f"{mu[0]:.4f}"
        # the page's emulator at random points of the box, every output and level
        rng = np.random.default_rng(seed)
        X = em.box[:, 0] + rng.random((n_points, len(names))) * (em.box[:, 1] - em.box[:, 0])
        levels = page.evaluate("Array.from(document.querySelectorAll('#level option')).map(o => o.value)")
        assert levels == H.page_levels(em), levels
        worst = 0.0
        for o in em.models:
            for lv in levels:
                js = np.array(page.evaluate(
                    "([o, l, X]) => X.map(x => { const p = window.mixsphReport.predict(o, l, x);"
                    " return [p.mean, p.sd]; })", [o, lv, X.tolist()]))
                mu, sd = H.python_predict(em, o, lv, X)
                err = max(np.max(np.abs(js[:, 0] - mu)), np.max(np.abs(js[:, 1] - sd)))
                assert err <= TOL, f"{o} at {lv}: the page differs from Python by {err:.3g}"
                worst = max(worst, err)
        assert_page_ok(page, errors)
        if screenshot:
            page.screenshot(path=screenshot, full_page=True)
        return worst
    finally:
        page.close()


def test_the_study_page_predicts_as_python_in_chromium(study, browser, tmp_path):
    folder, em = study
    path = os.path.join(folder, "report.html")
    assert os.path.isfile(path), "emulate study's ending wrote no report.html"
    shot = str(tmp_path / "study.png")
    worst = check_study_page(browser, path, em, screenshot=shot)
    print(f"the page's emulator against Python's at 20 points, every output and level: largest "
          f"difference {worst:.2g}")
    assert worst < TOL
    assert os.path.getsize(shot) > 50_000
    # self-contained: no address outside the page (Plotly's bundle inlined)
    html = open(path, encoding="utf-8").read()
    assert not re.search(r"<script[^>]+src=", html) and not re.search(r"<link[^>]+href=", html)


def _rewrite(path, out, change):
    """A copy of a page with its data block changed by change(text) -> text."""
    html = open(path, encoding="utf-8").read()
    head, rest = html.split('<script type="application/json" id="page-data">', 1)
    blob, tail = rest.split("</script>", 1)
    with open(out, "w", encoding="utf-8") as f:
        f.write(head + '<script type="application/json" id="page-data">' + change(blob)
                + "</script>" + tail)
    return out


def _edit(fn):
    def change(blob):
        d = json.loads(blob)
        fn(d)
        return json.dumps(d).replace("</", "<\\/")
    return change


def _scale_length(d):
    f = d["emulator"]["outputs"]["max_run_up_Z"]["gps"][0]["factors"][0]
    f["ls"] = [v * 1.001 for v in f["ls"]]


def _scale_length_no_self_check(d):
    _scale_length(d)
    d["checks"] = []


@pytest.mark.parametrize("how, change", [
    ("the data cut short", lambda blob: blob[: len(blob) // 2]),
    ("a length scale changed", _edit(_scale_length)),
    ("a length scale changed, no self-check", _edit(_scale_length_no_self_check)),
])
def test_the_check_fails_when_the_page_data_is_broken(study, browser, tmp_path, how, change):
    folder, em = study
    bad = _rewrite(os.path.join(folder, "report.html"), str(tmp_path / "broken.html"), change)
    with pytest.raises(AssertionError) as e:
        check_study_page(browser, bad, em)
    print(f"{how}: {str(e.value).splitlines()[0][:300]}")


def make_sweep(out):
    """A sweep folder of 12 stand-in runs at one dx and a failed one."""
    from tools.dss.store import open_store
    st = open_store(out, "parquet")
    rng = np.random.default_rng(2)
    for i in range(12):
        s = {"scenario_id": f"s{i:02d}", "reservoir_level": 0.40 + 0.01 * i,
             "phi": float(25 + 15 * rng.random()), "saturated": i % 2, "dx": 0.04}
        st.append(RF.run_result(s))
    st.append({"scenario_id": "bad", "reservoir_level": 0.9, "phi": 30.0, "saturated": 0,
               "dx": 0.04, "status": "failed", "error": "ValueError: reservoir_level = 0.9 outside",
               "finished_at": "1"})
    st.compact()
    with open(os.path.join(out, "sweep.json"), "w") as f:
        json.dump({"stop_time": 1.6, "step": 0.05, "dx": 0.04, "fixed": {}}, f)
    return out


def test_the_sweep_page_sorts_its_runs_and_shows_a_runs_monitors(browser, tmp_path):
    out = make_sweep(str(tmp_path / "sweep"))
    path = H.write_page(out, crest=850.0)
    page, errors = open_page(browser, path)
    try:
        assert_page_ok(page, errors)
        col = page.evaluate("Array.from(document.querySelectorAll('#runs-table th')).map(t => t.textContent)")
        j = col.index("max_run_up")
        first = lambda: page.evaluate(f"document.querySelector('#runs-table tbody tr').children[{j}].textContent")  # noqa: E731
        page.click(f"#runs-table th:nth-child({j + 1})")
        lo = first()
        page.click(f"#runs-table th:nth-child({j + 1})")
        hi = first()
        assert float(lo) < float(hi), (lo, hi)
        # a run's monitors: the run-up series of the clicked run, drawn (after another run's)
        page.click("#runs-table tbody tr:nth-child(2)")
        page.click("#runs-table tbody tr:nth-child(1)")
        y = page.evaluate("document.getElementById('run-plot').data.find(t => t.name === 'run_up').y")
        assert max(y) == pytest.approx(float(hi), rel=1e-5)
        assert page.locator("#run-plot .main-svg .scatterlayer .trace").count() >= 3
        assert page.locator("#exceedance-plot .main-svg").count() > 0
        assert_page_ok(page, errors)
    finally:
        page.close()


@pytest.mark.parametrize("mode", ["product", "separate"])
def test_a_sweeps_emulator_predicts_in_the_page_as_in_python(browser, tmp_path, mode):
    """A sweep folder with an emulator of its runs (emulate fit's emulator.json): the same
    panel and checks as a study's, with the single-fidelity emulator (a binary input in the
    product kernel, or a GP per level routed by it)."""
    from tools.dss import emulator as E
    from tools.dss.store import open_store
    out = make_sweep(str(tmp_path / "sweep"))
    em = E.from_results(open_store(out).latest(), outputs=["max_run_up", "max_run_up_Z"],
                        inputs=["reservoir_level", "phi", "saturated"])
    for o in em.Y:
        em.fit_output(o, mode=mode, restarts=0, cv=False)
    em.save(os.path.join(out, "emulator.json"))
    em = E.Emulator.from_json(json.load(open(os.path.join(out, "emulator.json"))))
    worst = check_study_page(browser, H.write_page(out, crest=850.0), em)
    print(f"mode {mode}: largest difference {worst:.2g}")


def test_the_run_page_shows_monitors_profiles_and_the_particles(browser, tmp_path):
    run = RF.make_run_dir(str(tmp_path / "run"), n_snap=5)
    path = H.write_page(run)
    page, errors = open_page(browser, path)
    try:
        assert_page_ok(page, errors)
        page.wait_for_function("document.getElementById('animation')._transitionData &&"
                               " document.getElementById('animation')._transitionData._frames.length === 5")
        page.select_option("#monitor", "kinetic_energy")
        y = page.evaluate("document.getElementById('monitor-plot').data[0].y")
        assert max(y) == pytest.approx(50 * np.exp(-1.0), rel=1e-3)
        assert page.evaluate("document.getElementById('profile-plot').data.length") == 1
        assert_page_ok(page, errors)
    finally:
        page.close()


def test_page_refuses_a_folder_that_is_no_study_sweep_or_run(tmp_path):
    r = subprocess.run([sys.executable, "-m", "tools.dss", "page", str(tmp_path)], cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert "neither a study (mf_emulator.json), a sweep" in r.stderr, r.stderr


def test_every_fmu_parameter_names_its_case_key_for_the_replays():
    from tools.dss import replay as RP
    keys = RP.case_keys(os.path.join(ROOT, "modelDescription.xml"))
    from fmpy import read_model_description
    md = read_model_description(os.path.join(ROOT, "modelDescription.xml"))
    params = {v.name for v in md.modelVariables if v.causality == "parameter"}
    assert set(keys) == params - {"case_file", "threads"}, sorted(params - set(keys))
    assert keys["phi"] == "parameters.phi" and keys["dx"] == "numerics.dx"
    assert keys["implicit_viscosity"] == "numerics.viscosity"
    assert keys["output_interval"] == "output.monitor_interval"


def test_a_replayed_run_has_the_fmu_runs_max_run_up(browser, tmp_path):
    """A scenario run by the FMU and replayed with mixsph (coarse and short) gives the same max
    run-up, and the replay has the snapshots the page animates; the run page of this real
    mixsph folder opens without error."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from tool_helpers import built
    from tools.dss import fmu_run, replay as RP
    mixsph = built("mixsph")
    fmu = built("LandslideWave.fmu")
    scen = {"scenario_id": "r1", "reservoir_level": 0.46, "phi": 30.0, "dx": 0.05}
    res = fmu_run.run_scenario(fmu_run.read_fmu_bytes(fmu), {k: v for k, v in scen.items()
                                                           if k != "scenario_id"},
                               {"stop_time": 0.4, "step": 0.05, "threads": 1})
    assert res["status"] == "ok", res["error"]
    done = RP.replay(str(tmp_path), [scen], fmu, 0.4, mixsph=mixsph, snapshots=4, log=print)
    rd = H.run_data(done["r1"])
    assert rd["summary"]["outputs"]["run_up"]["max"] == pytest.approx(res["max_run_up"], abs=1e-9)
    assert len(rd["frames"]) == 5
    page, errors = open_page(browser, H.write_page(done["r1"]))
    try:
        assert_page_ok(page, errors)
        assert page.locator("#animation .main-svg").count() > 0
        assert page.evaluate("document.getElementById('monitor-plot').data[0].y.length") > 10
    finally:
        page.close()
