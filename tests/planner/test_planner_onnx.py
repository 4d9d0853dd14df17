"""The ONNX depth path, with tiny models built here by onnx.helper (no downloads)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
import pytest
from onnx import TensorProto, helper

from rti_rig.core.errors import ConfigError, ScheduleError
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.make_plan import plan_with_report
from rti_rig.planner.topography import DepthModelSpec, depth_from_onnx

DOME = DomeGeometry(fibonacci_cap(40, 5.0, 88.0), tuple(f"l{i:02d}.png" for i in range(40)))


def build_model(path: Path, size: int, op: str = "mean", out_4d: bool = True) -> Path:
    """A (1,3,size,size) → depth graph: channel mean, or sqrt / reciprocal of it (NaN, inf)."""
    x = helper.make_tensor_value_info("image", TensorProto.FLOAT, [1, 3, size, size])
    shape = [1, 1, size, size] if out_4d else [1, size, size]
    y = helper.make_tensor_value_info("depth", TensorProto.FLOAT, shape)
    nodes = [helper.make_node("ReduceMean", ["image"], ["m"], axes=[1], keepdims=1)]
    last = "m"
    if op == "sqrt":  # negative normalised values → NaN in part of the map
        nodes.append(helper.make_node("Sqrt", ["m"], ["s"]))
        last = "s"
    elif op == "inf":  # x / 0 → ±inf or NaN everywhere
        zero = helper.make_tensor("zero", TensorProto.FLOAT, [1], [0.0])
        nodes.append(helper.make_node("Constant", [], ["z"], value=zero))
        nodes.append(helper.make_node("Div", ["m", "z"], ["d"]))
        last = "d"
    if not out_4d:
        nodes.append(helper.make_node("Squeeze", [last, "ax"], ["sq"]))
        axes = helper.make_tensor("axes", TensorProto.INT64, [1], [1])
        nodes.insert(0, helper.make_node("Constant", [], ["ax"], value=axes))
        last = "sq"
    nodes.append(helper.make_node("Identity", [last], ["depth"]))
    graph = helper.make_graph(nodes, "tiny_depth", [x], [y])
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 8
    onnx.checker.check_model(model)
    onnx.save(model, str(path))
    return path


PLAIN = DepthModelSpec(input_size=(16, 16), mean=(0, 0, 0), std=(1, 1, 1))


def ramp_preview(h: int = 40, w: int = 60) -> np.ndarray:
    img = np.zeros((h, w, 3), dtype=np.uint8)
    img[:] = np.linspace(0, 255, w).astype(np.uint8)[None, :, None]
    return img


@pytest.mark.parametrize("out_4d", [True, False])
def test_preprocessing_and_resize_back(tmp_path: Path, out_4d: bool) -> None:
    model = build_model(tmp_path / "m.onnx", 16, out_4d=out_4d)
    depth = depth_from_onnx(ramp_preview(), model, PLAIN)
    assert depth.shape == (40, 60)
    # inverse depth "bright = near": the ramp's bright right side is the nearest (highest)
    assert depth[:, -5:].mean() > depth[:, :5].mean() + 0.5
    assert np.allclose(depth[:, 30], depth[0, 30])  # constant down each column


def test_imagenet_normalisation_is_applied(tmp_path: Path) -> None:
    model = build_model(tmp_path / "m.onnx", 8)
    grey = np.full((8, 8, 3), 255, dtype=np.uint8)
    spec = DepthModelSpec(input_size=(8, 8))  # default ImageNet mean/std
    mean, std = np.array(spec.mean), np.array(spec.std)
    expected = float(np.mean((1.0 - mean) / std))
    assert np.allclose(depth_from_onnx(grey, model, spec), expected, atol=1e-5)
    lerés = DepthModelSpec(input_size=(8, 8), output="depth")
    assert np.allclose(depth_from_onnx(grey, model, lerés), -expected, atol=1e-5)


def test_linear_uint16_preview_is_gamma_encoded_for_the_network(tmp_path: Path) -> None:
    model = build_model(tmp_path / "m.onnx", 4)
    mid = np.full((4, 4), int(0.2140 * 65535), dtype=np.uint16)  # linear 0.214 ≈ sRGB 0.5
    out = depth_from_onnx(mid, model, DepthModelSpec((4, 4), (0, 0, 0), (1, 1, 1)))
    assert np.allclose(out, 0.5, atol=0.01)


def test_missing_and_broken_models_are_config_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="not found"):
        depth_from_onnx(ramp_preview(), tmp_path / "nope.onnx")
    bad = tmp_path / "bad.onnx"
    bad.write_bytes(b"not a model")
    with pytest.raises(ConfigError, match="cannot load"):
        depth_from_onnx(ramp_preview(), bad)
    wrong = build_model(tmp_path / "m.onnx", 16)
    with pytest.raises(ConfigError, match="input_size"):
        depth_from_onnx(ramp_preview(), wrong, DepthModelSpec(input_size=(32, 32)))


def test_plan_with_a_depth_model(tmp_path: Path) -> None:
    model = build_model(tmp_path / "m.onnx", 256)
    sched, report = plan_with_report(
        ramp_preview(), DOME, 6, "optimal", preview_light=(0.0, 45.0), depth_model=model
    )
    assert len({s.led for s in sched.steps}) == 6
    assert report.relief_source == "depth model m.onnx"


def test_partly_nan_depth_is_repaired_and_reported(tmp_path: Path) -> None:
    model = build_model(tmp_path / "m.onnx", 256, op="sqrt")
    # ImageNet normalisation makes dark pixels negative → sqrt gives NaN on the dark half
    img = ramp_preview()
    img[:, :25] = 0
    spec_default = DepthModelSpec(input_size=(256, 256))
    raw = depth_from_onnx(img, model, spec_default)
    assert np.isnan(raw).any() and np.isfinite(raw).any()
    _, report = plan_with_report(
        img, DOME, 6, "kmeans", preview_light=(0.0, 45.0), depth_model=model
    )
    assert report.nonfinite_relief_repaired > 0
    assert any("NaN/infinite" in note for note in report.notes)


def test_all_infinite_depth_is_a_clear_error(tmp_path: Path) -> None:
    model = build_model(tmp_path / "m.onnx", 256, op="inf")
    with pytest.raises(ScheduleError, match=r"m\.onnx.*NaN or infinite"):
        plan_with_report(ramp_preview(), DOME, 6, "optimal", depth_model=model)
