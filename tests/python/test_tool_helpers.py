"""tool_helpers.built: a test that needs a missing build fails in CI and is skipped elsewhere."""
import pytest

import tool_helpers


def test_a_missing_build_fails_in_ci(monkeypatch, tmp_path):
    monkeypatch.setattr(tool_helpers, "BUILD", str(tmp_path))
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match=r"mixsph is not built.*CI=true"):
        tool_helpers.built("mixsph")


def test_a_missing_build_is_skipped_outside_ci(monkeypatch, tmp_path):
    monkeypatch.setattr(tool_helpers, "BUILD", str(tmp_path))
    monkeypatch.delenv("CI", raising=False)
    with pytest.raises(pytest.skip.Exception, match=r"LandslideWave.fmu is not built \(build it with ninja\)"):
        tool_helpers.built("LandslideWave.fmu", how="ninja")


def test_a_built_file_is_returned_in_ci(monkeypatch, tmp_path):
    (tmp_path / "mixsph").write_text("")
    monkeypatch.setattr(tool_helpers, "BUILD", str(tmp_path))
    monkeypatch.setenv("CI", "true")
    assert tool_helpers.built("mixsph") == str(tmp_path / "mixsph")
