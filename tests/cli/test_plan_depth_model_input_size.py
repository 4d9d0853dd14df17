"""`rti-rig plan PREVIEW --depth-model M.onnx` feeds the model the image size it declares.

Why: every model was fed 256×256 (MiDaS v2.1 small's size), so a Depth Anything export (518×518)
or a MiDaS at 384×384, both named in --depth-model's help, was refused: "running the model on a
256×256 input failed (...); check input_size", a setting the command line does not offer. The
models here are built by onnx.helper (no downloads).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
from conftest import CONFIGS, said
from onnx import TensorProto, helper
from PIL import Image
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
RIG = CONFIGS / "simulated_dome.toml"


def _model(path: Path, shape: list[int | str]) -> Path:
    """An image → relief graph (the channels' mean) whose input declares ``shape``."""
    x = helper.make_tensor_value_info("image", TensorProto.FLOAT, shape)
    y = helper.make_tensor_value_info("depth", TensorProto.FLOAT, None)
    node = helper.make_node("ReduceMean", ["image"], ["depth"], axes=[1], keepdims=1)
    graph = helper.make_graph([node], "declared", [x], [y])
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 8
    onnx.save(model, str(path))
    return path


def _plan(tmp_path: Path, model: Path) -> tuple[int, str]:
    preview = tmp_path / "preview.png"
    yy, xx = np.mgrid[0:48, 0:48]
    Image.fromarray((60 + 2 * xx + yy).astype(np.uint8)).save(preview)
    r = runner.invoke(
        app,
        [
            "plan", str(preview), "--rig", str(RIG), "--preview-light", "112.5,55",
            "--depth-model", str(model), "--out", str(tmp_path / "plan.lp"),
        ],
    )  # fmt: skip
    return r.exit_code, said(r)


def test_a_model_declaring_384_by_384_is_fed_that(tmp_path: Path) -> None:
    code, text = _plan(tmp_path, _model(tmp_path / "midas 384.onnx", [1, 3, 384, 384]))

    assert code == 0, text
    assert "relief from depth model midas 384.onnx" in text, text
    assert (tmp_path / "plan.lp").is_file()


def test_a_model_taking_one_channel_is_refused_saying_what_it_declares(tmp_path: Path) -> None:
    code, text = _plan(tmp_path, _model(tmp_path / "grey.onnx", [1, 1, 64, 64]))

    assert code == 2, text
    assert "its input is declared 1×1×64×64 tensor(float): rti-rig feeds one RGB image" in text
    assert "check input_size" not in text, text  # no option sets it
    assert "Traceback" not in text and not (tmp_path / "plan.lp").exists()
