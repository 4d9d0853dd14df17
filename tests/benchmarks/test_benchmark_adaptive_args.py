"""``benchmarks.adaptive`` refuses a draw count its paired verdicts cannot use, before it runs
anything (it crashed in the paired test after minutes of simulation)."""

from __future__ import annotations

import pytest

from benchmarks import adaptive


@pytest.mark.parametrize("args", [["--sim-draws", "1"], ["--real-draws", "1"]])
def test_one_draw_is_refused_up_front(args: list[str], capsys) -> None:
    with pytest.raises(SystemExit) as caught:
        adaptive.main(args)
    assert caught.value.code == 2
    assert "at least 2" in capsys.readouterr().err
