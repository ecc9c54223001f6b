"""tools/gain_reach.py rejects a bad camera height or --json path by name, exit 2, before any
rendering."""

import pytest

from mobigrasp.tools import gain_reach


@pytest.mark.parametrize("hc", ["nan", "inf", "-0.3", "7", "high"])
def test_a_bad_camera_height_exits_2_naming_it(hc, capsys):
    with pytest.raises(SystemExit) as e:
        gain_reach.main(["--hc", hc])
    assert e.value.code == 2
    assert "--hc" in capsys.readouterr().err


def test_a_json_path_that_is_a_folder_exits_2(tmp_path, capsys):
    for bad in (tmp_path, tmp_path / "missing" / "out.json"):
        with pytest.raises(SystemExit) as e:
            gain_reach.main(["--json", str(bad)])
        assert e.value.code == 2
        assert "--json" in capsys.readouterr().err
