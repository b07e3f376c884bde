"""Column descriptions without YADE: mass properties against integration of the solid,
contact areas and plates, statics, validation, the paper's columns as special cases."""
import json
import math

import numpy as np
import pytest
from scipy import integrate

from pipeline.files import InputError
from pipeline.scenario import Block, Column, scene_params
from pipeline.scenario.bodies import ColumnSpec
from pipeline.scenario.column_format import example_names
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.outline import Outline, contact_outline, perimeter_points
from pipeline.scenario.solids import Box, Frustum

DENSITY = 2700.0


def integrated_frustum(a, b, h, density=DENSITY):
    """Mass, centroid height and (Ixx, Izz) of a frustum by scipy.integrate over its volume
    (cylindrical coordinates: z, theta, r up to the radius at z)."""
    def over_volume(f):
        return integrate.tplquad(lambda r, th, z: f(r, th, z) * r, 0, h, 0, 2 * math.pi,
                                 0, lambda z, th: a + (b - a) * z / h,
                                 epsabs=1e-13, epsrel=1e-11)[0]
    mass = density * over_volume(lambda r, th, z: 1.0)
    zc = density * over_volume(lambda r, th, z: z) / mass
    ixx = density * over_volume(lambda r, th, z: (r * math.sin(th)) ** 2 + (z - zc) ** 2)
    izz = density * over_volume(lambda r, th, z: r * r)
    return mass, zc, ixx, izz


@pytest.mark.parametrize("a, b, h", [(0.95, 0.74, 0.9),      # a tapering Doric drum
                                     (0.74, 0.99, 0.51),     # an echinus, wider on top
                                     (0.29, 0.29, 3.5),      # the paper's monolith
                                     (0.5, 0.05, 0.3)])      # almost a cone
def test_frustum_mass_properties_match_integration(a, b, h):
    m, zc, (ixx, iyy, izz) = Frustum(h, 2 * a, 2 * b).mass_properties(DENSITY)
    ref = integrated_frustum(a, b, h)
    assert m == pytest.approx(ref[0], rel=1e-9)
    assert zc == pytest.approx(ref[1], rel=1e-9)
    assert ixx == iyy == pytest.approx(ref[2], rel=1e-8)
    assert izz == pytest.approx(ref[3], rel=1e-8)


def test_box_mass_properties_match_integration():
    w, d, h = 2.07, 1.3, 0.25
    m, zc, inertia = Box(h, w, d).mass_properties(DENSITY)

    def over_volume(f):
        return DENSITY * integrate.tplquad(f, 0, h, -d / 2, d / 2, -w / 2, w / 2)[0]
    assert m == pytest.approx(over_volume(lambda x, y, z: 1.0), rel=1e-10)
    assert zc == pytest.approx(over_volume(lambda x, y, z: z) / m, rel=1e-10)
    ref = [over_volume(lambda x, y, z: y * y + (z - zc) ** 2),
           over_volume(lambda x, y, z: x * x + (z - zc) ** 2),
           over_volume(lambda x, y, z: x * x + y * y)]
    assert inertia == pytest.approx(ref, rel=1e-9)


def test_joined_offset_blocks_match_monte_carlo():
    """A capital carved in one stone: echinus (frustum) and an off-centre abacus (box)."""
    a, b, h1 = 0.74, 0.99, 0.51
    w, d, h2, off = 2.04, 1.8, 0.35, (0.1, -0.05)
    g = ColumnGeometry.from_dict({"name": "capital", "density": DENSITY, "blocks": [
        {"shape": "frustum", "height": h1, "bottom_diameter": 2 * a, "top_diameter": 2 * b},
        {"shape": "box", "height": h2, "width": w, "depth": d, "offset_m": list(off),
         "joined": True}]})
    (body,) = g.bodies()
    rng = np.random.default_rng(1)
    n = 2_000_000
    half = max(b, w / 2 + abs(off[0]), d / 2 + abs(off[1]))
    lo, hi = np.array([-half, -half, 0.0]), np.array([half, half, h1 + h2])
    p = lo + (hi - lo) * rng.random((n, 3))
    in_frustum = (p[:, 2] <= h1) & (np.hypot(p[:, 0], p[:, 1]) <= a + (b - a) * p[:, 2] / h1)
    in_box = (p[:, 2] > h1) & (np.abs(p[:, 0] - off[0]) <= w / 2) & \
        (np.abs(p[:, 1] - off[1]) <= d / 2)
    q = p[in_frustum | in_box]
    mass = DENSITY * np.prod(hi - lo) * len(q) / n
    com = q.mean(axis=0)
    r = q - com
    tensor = mass * (np.eye(3) * (r * r).sum(1).mean() - r.T @ r / len(q))
    assert body.mass == pytest.approx(mass, rel=3e-3)
    assert body.com == pytest.approx(com, abs=2e-3)
    assert body.inertia == pytest.approx(tensor, rel=5e-3, abs=2e-3 * np.abs(tensor).max())
    assert abs(body.inertia[0, 2]) > 1e-3 * np.abs(body.inertia).max()   # the offset tilts
    #                                                   the principal axes


# ---------------------------------------------------------------- contact areas and plates
def column(*blocks, density=DENSITY):
    return ColumnGeometry.from_dict({"name": "test", "density": density, "blocks": list(blocks)})


def frustum(h, d0, d1=None, **extra):
    return {"shape": "frustum", "height": h, "bottom_diameter": d0,
            "top_diameter": d0 if d1 is None else d1, **extra}


def box(h, w, d=None, **extra):
    return {"shape": "box", "height": h, "width": w, "depth": w if d is None else d, **extra}


def test_wide_capital_rests_on_the_shaft_top_rim():
    g = column(frustum(3.0, 0.6, 0.5), frustum(0.4, 0.7, 1.0))
    _, capital = g.bodies()
    assert capital.contact.kind == "circle" and capital.contact.radius == 0.25
    edges = [r for r in capital.rims if r["role"] == "edge" and r["z"] == 0.0]
    assert edges and edges[0]["outline"].radius == 0.35     # its own overhanging rim


def test_drum_on_a_wider_base_rests_on_its_own_rim():
    g = column(box(0.3, 1.6), frustum(1.0, 1.2))
    base, drum = g.bodies()
    assert drum.contact.kind == "circle" and drum.contact.radius == 0.6
    assert base.contact.kind == "polygon" and len(base.contact.vertices) == 4


def test_offset_drums_touch_on_the_overlap_of_their_faces():
    below, above = Outline.circle(0.5), Outline.circle(0.5, (0.2, 0.0))
    lens = contact_outline(below, above)
    points = perimeter_points(lens.polygon(), 16)
    assert len(points) == 16
    for centre in ((0.0, 0.0), (0.2, 0.0)):
        assert np.all(np.hypot(*(points - centre).T) <= 0.5 + 1e-9)
    # every point is on the boundary of one of the two circles
    on = np.minimum(abs(np.hypot(*points.T) - 0.5), abs(np.hypot(*(points - (0.2, 0)).T) - 0.5))
    assert on.max() < 1e-3
    with pytest.raises(InputError, match="overlap"):
        contact_outline(below, Outline.circle(0.5, (0.98, 0.0)))


def test_box_rims_carry_their_corners():
    points = perimeter_points(Outline.rectangle(0.08, 0.045).polygon(), 16)
    assert sorted(map(tuple, np.round(points, 6))) == sorted(
        [(-0.04, -0.0225), (0.04, -0.0225), (0.04, 0.0225), (-0.04, 0.0225)])


@pytest.mark.parametrize("name", ["doric-peristyle", "roman-granite", "capital", "offset"])
def test_plate_covers_the_contact_area_of_the_body_above(name):
    geometry = {"capital": column(frustum(3.0, 0.6, 0.5), frustum(0.4, 0.7, 1.0)),
                "offset": column(frustum(1.0, 1.0), frustum(1.0, 1.0, offset_m=[0.15, 0.1]),
                                 box(0.4, 1.2, offset_m=[-0.1, 0.0]))
                }.get(name) or ColumnGeometry.load(name)
    rim_r = 0.005
    scene = ColumnSpec("drums", "drums", 0.0, 0.0, geometry).scene(16)
    for lower, upper in zip(scene["bodies"], scene["bodies"][1:]):
        base = next(r for r in upper["rims"] if r["role"] == "base")
        if base["kind"] == "circle":
            ang = 2 * np.pi * np.arange(64) / 64
            xy = base["centre"] + base["radius"] * np.column_stack([np.cos(ang), np.sin(ang)])
        else:
            xy = np.array(base["points"])
        n = np.array(base["normal"])
        local = np.column_stack([xy, base["z"] - (xy @ n[:2]) / n[2]])
        world = np.array(upper["centre"]) + local @ np.array(upper["rotation"]).T
        # in the lower body's frame, on its top face and inside its plate
        R = np.array(lower["rotation"])
        rel = (world - lower["centre"]) @ R - lower["plate"]["centre"]
        assert np.abs(rel[:, 2]).max() < 1e-9
        assert np.all(np.abs(rel[:, :2]) <= np.array(lower["plate"]["half_size"]) + rim_r)


# ---------------------------------------------------------------- statics
def test_uplift_ratio_of_a_cylinder_is_d_over_h():
    g = ColumnGeometry.monolith(3.5, 3.5 / 6, 2960.0)
    assert g.uplift_ratio() == 1 / 6
    assert ColumnGeometry.drums(3.5, 3.5 / 6, 7, 2960.0).uplift_ratio() == pytest.approx(1 / 6)
    assert column(box(3.0, 0.6, 0.5)).uplift_ratio() == pytest.approx(0.5 / 3.0)


def test_wide_heavy_capital_lowers_the_uplift_threshold_below_d_over_h():
    shaft = frustum(3.0, 0.5, 0.45)
    g = column(shaft, box(0.35, 0.9))
    (m1, z1, _), (m2, z2, _) = (Frustum(3.0, 0.5, 0.45).mass_properties(DENSITY),
                                Box(0.35, 0.9, 0.9).mass_properties(DENSITY))
    zc = (m1 * z1 + m2 * (3.0 + z2)) / (m1 + m2)
    assert g.uplift_ratio() == pytest.approx(0.25 / zc, rel=1e-12)
    assert g.uplift_ratio() < 0.5 / 3.35 < 0.5 / 3.0
    # the same stack's monolith rocks on the same base at the same threshold
    assert g.monolithic().uplift_ratio() == pytest.approx(g.uplift_ratio(), rel=1e-12)


def test_out_of_plumb_column_rocks_earlier_toward_its_lean():
    plumb = column(frustum(3.5, 0.6))
    leaning = column(frustum(3.5, 0.6, tilt_deg=2.0, tilt_azimuth_deg=45.0))
    lean = math.tan(math.radians(2.0))
    # the centre of mass moves toward the edge by zc tan(tilt) (wedge joint, z ~ cos)
    expected = (0.3 - 1.75 * math.sin(math.radians(2.0))) / (1.75 * math.cos(math.radians(2.0)))
    assert leaning.uplift_ratio() == pytest.approx(expected, rel=1e-6)
    assert leaning.uplift_ratio() < plumb.uplift_ratio() - 0.9 * lean
    body = leaning.bodies()[0]
    axis = body.rotation[:, 2]
    assert math.degrees(math.acos(axis[2])) == pytest.approx(2.0)
    assert math.degrees(math.atan2(axis[0], axis[1])) == pytest.approx(45.0)


def test_verification_block_is_placed_on_its_edge_as_before():
    h, w, d, th = 0.4, 0.08, 0.045, 0.1
    (spec,) = [c for c in scene_params(block=Block(h, w, d, 2960.0, th)).columns]
    (body,) = spec["bodies"]
    Ry = np.array([[math.cos(th), 0, math.sin(th)], [0, 1, 0], [-math.sin(th), 0, math.cos(th)]])
    pivot = np.array([w / 2, 0, 0])
    assert body["centre"] == pytest.approx(pivot + Ry @ (np.array([0, 0, h / 2]) - pivot),
                                           abs=1e-15)
    assert np.array(body["rotation"]) == pytest.approx(Ry, abs=1e-15)
    assert not spec["settles"] and spec["uplift_ratio"] == 0.0


# ---------------------------------------------------------------- validation
@pytest.mark.parametrize("data, words", [
    ({"density": 2700, "blocks": [frustum(1, 1)]}, "missing key 'name'"),
    ({"name": "x", "blocks": [frustum(1, 1)]}, "missing key 'density'"),
    ({"name": "x", "density": 2700}, "missing key 'blocks'"),
    ({"name": "x", "density": 2700, "blocks": []}, "non-empty list"),
    ({"name": "x", "density": 2700, "blocks": [{"height": 1}]}, "missing key 'shape'"),
    ({"name": "x", "density": 2700, "blocks": [{"shape": "cone", "height": 1}]},
     "unknown shape 'cone'"),
    ({"name": "x", "density": 2700, "blocks": [{"shape": "box", "height": 1, "width": 1}]},
     "missing key(s) depth"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 0.0)]}, "must be positive"),
    ({"name": "x", "density": 2700, "blocks": [frustum(-2, 1)]}, "height must be positive"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 1, bottom_diamter=1)]},
     "unknown key(s) bottom_diamter"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 250.0)]}, "outside the allowed range"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 0.01)]}, "outside the allowed range"),
    ({"name": "x", "density": 27, "blocks": [frustum(1, 1)]}, "density 27"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 1, density="heavy")]}, "density"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 1, tilt_deg=60)]}, "tilt_deg 60"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 1, offset_m=[0.1])]}, "offset_m"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 1, joined=True)]}, "bottom block"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 1, tilt_mode="lean")]}, "tilt_mode"),
    ({"name": "x", "density": 2700, "blocks": [frustum(25, 1), frustum(25, 1)]}, "at most 40"),
    ({"name": "x", "density": 2700, "blocks": [frustum(8, 0.5, tilt_deg=10)]}, "cannot stand"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 1), frustum(1, 1, offset_m=[1.2, 0])]},
     "overlap"),
    ({"name": "x", "density": 2700, "blocks": [frustum(1, 1)], "colour": "white"},
     "unknown key(s) colour"),
    ([1, 2], "expected a JSON object"),
])
def test_bad_descriptions_give_one_line(data, words):
    with pytest.raises(InputError) as info:
        ColumnGeometry.from_dict(data, where="col.json")
    message = str(info.value)
    assert "\n" not in message and message.startswith("col.json")
    assert words in message


def test_bad_files_give_one_line(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    for arg, words in ((bad, "not a readable column description"),
                       (tmp_path / "missing.json", "no such file or shipped example"),
                       ("no-such-example", "no such file or shipped example")):
        with pytest.raises(InputError) as info:
            ColumnGeometry.load(arg)
        assert "\n" not in str(info.value) and words in str(info.value)


def test_yaml_and_json_give_the_same_column(tmp_path):
    yaml = pytest.importorskip("yaml")
    data = ColumnGeometry.load("roman-granite").to_dict()
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(data))
    (tmp_path / "c.json").write_text(json.dumps(data))
    assert ColumnGeometry.load(tmp_path / "c.yaml") == ColumnGeometry.load(tmp_path / "c.json")


# ---------------------------------------------------------------- the paper's columns
def test_default_columns_are_the_shipped_paper_columns():
    drums, mono = Column("both").specs()
    assert drums.geometry.blocks == ColumnGeometry.load("hinzen2009-drums").blocks
    assert mono.geometry.blocks == ColumnGeometry.load("hinzen2009-monolith").blocks
    for spec, name in ((drums, "hinzen2009-drums"), (mono, "hinzen2009-monolith")):
        shipped = ColumnSpec(spec.name, spec.kind, spec.x, spec.y, ColumnGeometry.load(name))
        ours, theirs = spec.scene(16), shipped.scene(16)
        assert ours["bodies"] == theirs["bodies"]          # the same params.json bodies
        assert ours["uplift_ratio"] == theirs["uplift_ratio"]


def test_default_scene_bodies_are_the_paper_columns():
    params = scene_params(columns=Column("both").specs())
    drums, mono = params.columns
    assert [b["centre"] for b in drums["bodies"]] == [[-1.5, 0.0, 0.25 + 0.5 * k]
                                                      for k in range(7)]
    d = 3.5 / 6
    assert drums["bodies"][0]["mass"] == 2960.0 * math.pi * (d / 2) ** 2 * 0.5
    assert mono["bodies"][0]["mass"] == pytest.approx(2772, rel=0.002)
    assert mono["uplift_ratio"] == pytest.approx(d / 3.5, rel=1e-15)      # tan(alpha)
    assert params.pedestal["contact_half_size"] == 12.0


def test_column_file_with_both_places_a_monolith_of_its_outline_beside_it():
    drums, mono = Column("both", column_file="doric-peristyle").specs()
    assert (drums.x, mono.x) == (-1.5, 1.5)
    assert len(drums.geometry.bodies()) == 12 and len(mono.geometry.bodies()) == 1
    (stone,) = mono.geometry.bodies()
    assert stone.mass == pytest.approx(sum(b.mass for b in drums.geometry.bodies()))
    assert [p.block.solid for p in stone.parts] == [b.solid for b in drums.geometry.blocks]
    (single,) = Column("monolithic", column_file="doric-peristyle").specs()
    assert single.x == 0.0 and single.geometry == mono.geometry


@pytest.mark.parametrize("name", example_names())
def test_shipped_examples_stand_and_cite_their_sources(name):
    g = ColumnGeometry.load(name)
    assert g.source and g.notes
    assert g.check()
    assert ColumnGeometry.from_dict(g.to_dict()) == g


def test_parthenon_column_dimensions():
    g = ColumnGeometry.load("doric-peristyle")
    assert g.height == pytest.approx(10.43)
    assert g.blocks[0].solid.bottom_diameter == pytest.approx(1.905)
    drums = [b for b in g.blocks if b.name and b.name.startswith("drum")]
    assert 10 <= len(drums) <= 12
    assert g.blocks[-1].solid.shape == "box" and g.blocks[-1].joined      # abacus
    assert len(g.bodies()) == len(drums) + 1                             # + the capital
