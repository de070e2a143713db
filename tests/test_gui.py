"""The inspector, driven off-screen: layers, k slider, picking, screenshots."""

import os

import numpy as np
import pytest

pytest.importorskip("pyvista")

from sr33.gui import pyvista  # noqa: E402

pv = pyvista(off_screen=True)

from sr33 import Reconstruction, k_neighbourhoods, reconstruct  # noqa: E402
from sr33.cli import main  # noqa: E402
from sr33.gui import COLOURS, LAYERS, Inspector  # noqa: E402
from sr33.io import load_reconstruction, read_points, save_reconstruction  # noqa: E402
from sr33.samplers import cube_lattice  # noqa: E402
from sr33.validators import mesh_stats  # noqa: E402
from tests.helpers import PAPER_SMALL, need, triangle_set  # noqa: E402


def red_pixels(img):
    r, g, b = COLOURS["open"]
    return int(((img[..., 0] > 240) & (img[..., 1] < 20) & (img[..., 2] < 20)).sum())


@pytest.fixture(scope="module")
def cube():
    pts = cube_lattice(6)
    return pts, reconstruct(pts, 12)


def plotter():
    return pv.Plotter(off_screen=True, window_size=(500, 400))


def test_every_layer_toggles_state_and_actors(cube):
    pts, rec = cube
    ins = Inspector(plotter(), pts, k=12, reconstruction=rec, truth=(pts, rec.triangles))
    for name in LAYERS:
        for on in (False, True):
            ins.set_layer(name, on)
            assert ins.state.layers[name] is on
            assert all(bool(a.GetVisibility()) is on for a in ins._actors.get(name, []))
    with pytest.raises(ValueError, match="layer must be one of"):
        ins.set_layer("nope", True)


def test_defect_colour_only_with_a_defect_and_the_layer_on(cube):
    pts, rec = cube
    broken = Reconstruction(**{**rec.__dict__, "triangles": rec.triangles[3:]})
    hole = int(rec.triangles[0, 0])
    p = plotter()
    ins = Inspector(p, pts, k=12, reconstruction=broken)
    assert ins.state.figures["open_edges"] > 0
    ins.look_at(hole, 3.0)
    assert red_pixels(p.screenshot(return_img=True)) > 100
    ins.set_layer("defects", False)
    assert red_pixels(p.screenshot(return_img=True)) == 0
    p2 = plotter()
    clean = Inspector(p2, pts, k=12, reconstruction=rec)
    clean.look_at(hole, 3.0)
    assert clean.state.figures["open_edges"] == 0
    assert red_pixels(p2.screenshot(return_img=True)) == 0


def test_k_slider_reruns_and_changes_the_figures():
    pts = read_points(need(PAPER_SMALL / "cutcube.obj"))
    p = plotter()
    ins = Inspector(p, pts, k=16)
    before = triangle_set(ins.rec.triangles)
    camera = list(p.camera_position)
    # drive the slider widget itself: set its value and fire its end event
    p.render()
    p.iren.initialize()
    rep = ins._slider.GetRepresentation()
    rep.SetValue(4)  # a k this small closes its last hole with a loop face
    ins._slider.InvokeEvent("EndInteractionEvent")
    assert ins.state.k == 4 and ins.rec.k == 4
    assert ins.rec.hole_faces >= 1
    assert triangle_set(ins.rec.triangles) != before
    assert ins.state.figures == {
        **ins.state.figures,
        **mesh_stats(ins.rec.triangles, ins.rec.vertices.shape[0]).as_dict(),
    }
    assert [tuple(x) for x in p.camera_position] == [tuple(x) for x in camera]


def test_picking_selects_the_sample_and_shows_its_neighbourhood(cube):
    pts, rec = cube
    ins = Inspector(plotter(), pts, k=12, reconstruction=rec)
    ins._on_pick(rec.vertices[37] + 1e-9)
    assert ins.state.picked == 37
    info = ins.pick(37)
    assert set(info["neighbourhood"]) == set(k_neighbourhoods(rec.vertices, 12).of(37).tolist())
    assert info["faces"] >= 3 and info["rng_degree"] >= 3
    assert len(ins._pick_actors) >= 2


def test_screenshot_and_side_by_side(cube, tmp_path):
    pts, rec = cube
    p = pv.Plotter(off_screen=True, shape=(1, 2), window_size=(800, 400))
    ins = Inspector(p, pts, k=12, reconstruction=rec, truth=(pts, rec.triangles))
    out = ins.screenshot(tmp_path / "x.png")
    assert os.path.getsize(out) > 1000


def test_reconstruction_round_trips_through_npz(cube, tmp_path):
    """Every field of the dataclass comes back (a field added later and not
    saved fails here)."""
    import dataclasses

    from sr33.selection import ExactReport

    _, rec = cube
    rec = dataclasses.replace(rec, hole_faces=3, exact=ExactReport(2, 1, 1, 5))
    back = load_reconstruction(save_reconstruction(tmp_path / "r.npz", rec))
    for f in dataclasses.fields(rec):
        a, b = getattr(back, f.name), getattr(rec, f.name)
        if isinstance(b, np.ndarray):
            assert np.array_equal(a, b), f.name
        elif f.name == "face_cycles":
            assert a.as_tuples() == b.as_tuples()
        else:
            assert a == b, f.name


def test_view_command_writes_a_screenshot(tmp_path, capsys):
    src = need(PAPER_SMALL / "cube.obj")
    out = tmp_path / "v.png"
    assert main(["view", str(src), "-k", "16", "--screenshot", str(out)]) == 0
    assert out.stat().st_size > 1000
    assert f"screenshot written to {out}" in capsys.readouterr().out


def test_view_without_display_says_how(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["view", str(need(PAPER_SMALL / "cube.obj"))]) == 2
    err = capsys.readouterr().err
    assert "no display to open a window on; render off-screen with --screenshot" in err
