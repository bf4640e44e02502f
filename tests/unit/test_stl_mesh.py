"""Tests of the mesh primitives, triangle surfaces and STL files of demcal.decks: surface areas,
closedness, orientation, STL round trips."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np
import pytest

from demcal.decks.mesh_primitives import (
    annulus,
    box_open_top,
    cylinder_shell,
    disc,
    quad,
    rectangle,
)
from demcal.decks.stl_file import StlFormatError, read_stl, write_stl_ascii, write_stl_binary
from demcal.decks.triangle_surface import (
    enclosed_volume,
    is_closed,
    merge,
    rotate_z,
    surface_area,
    translate,
    triangle_areas,
    triangle_normals,
)

R, H, N = 0.0366, 0.055, 64  # a dCylDp-20-sized cell: radius and height in m


def _polygon_factor(n: int) -> float:
    """Inscribed n-gon area / circle area."""
    return math.sin(2 * math.pi / n) / (2 * math.pi / n)


def test_triangle_area_and_normal_of_a_345_triangle() -> None:
    tri = np.array([[[0.0, 0.0, 1.0], [3.0, 0.0, 1.0], [0.0, 4.0, 1.0]]])
    assert triangle_areas(tri)[0] == pytest.approx(6.0)
    np.testing.assert_allclose(triangle_normals(tri)[0], [0.0, 0.0, 1.0])
    np.testing.assert_allclose(triangle_normals(tri[:, ::-1])[0], [0.0, 0.0, -1.0])


@pytest.mark.parametrize("n", [8, 64, 256])
def test_cylinder_shell_area(n: int) -> None:
    tris = cylinder_shell(R, 0.01, 0.01 + H, n)
    assert tris.shape == (2 * n, 3, 3)
    exact_polygon = 2 * n * R * math.sin(math.pi / n) * H
    assert surface_area(tris) == pytest.approx(exact_polygon, rel=1e-12)
    # against the true cylinder: relative error below the stated (pi/n)^2/6
    rel = 1 - surface_area(tris) / (2 * math.pi * R * H)
    assert 0 < rel <= (math.pi / n) ** 2 / 6


@pytest.mark.parametrize("normals", ["inward", "outward"])
def test_cylinder_shell_orientation(normals: str) -> None:
    centre = (0.2, -0.1)
    tris = cylinder_shell(R, 0.0, H, N, centre=centre, normals=normals)
    radial = tris.mean(axis=1)[:, :2] - np.array(centre)
    radial /= np.linalg.norm(radial, axis=1, keepdims=True)
    dots = np.einsum("ij,ij->i", triangle_normals(tris)[:, :2], radial)
    expected = -1.0 if normals == "inward" else 1.0
    # flat facets of an n-gon: the normal is radial up to the facet's half angle
    assert np.all(np.sign(dots) == expected)
    assert np.all(np.abs(dots) > math.cos(math.pi / N))
    np.testing.assert_allclose(triangle_normals(tris)[:, 2], 0.0, atol=1e-12)
    # all vertices lie on the circle
    r = np.linalg.norm(tris[..., :2] - np.array(centre), axis=-1)
    np.testing.assert_allclose(r, R, rtol=1e-12)


@pytest.mark.parametrize("n", [6, 64])
def test_disc_and_annulus_areas(n: int) -> None:
    d = disc(R, 0.3, n, centre=(1.0, 2.0))
    assert surface_area(d) == pytest.approx(0.5 * n * R**2 * math.sin(2 * math.pi / n))
    assert surface_area(d) == pytest.approx(math.pi * R**2 * _polygon_factor(n), rel=1e-12)
    assert 1 - _polygon_factor(n) <= (2 * math.pi / n) ** 2 / 6
    np.testing.assert_allclose(triangle_normals(d)[:, 2], 1.0)
    np.testing.assert_allclose(triangle_normals(disc(R, 0.0, n, normal_up=False))[:, 2], -1.0)
    a = annulus(0.5 * R, R, 0.0, n)
    expected = math.pi * (R**2 - (0.5 * R) ** 2) * _polygon_factor(n)
    assert surface_area(a) == pytest.approx(expected, rel=1e-12)
    np.testing.assert_allclose(triangle_normals(a)[:, 2], 1.0)
    np.testing.assert_allclose(
        triangle_normals(annulus(0.5 * R, R, 0.0, n, normal_up=False))[:, 2], -1.0
    )
    # the annulus is the disc minus the inner disc
    assert surface_area(a) == pytest.approx(
        surface_area(disc(R, 0.0, n)) - surface_area(disc(0.5 * R, 0.0, n)), rel=1e-12
    )


def test_closed_cylinder_volume_and_orientation() -> None:
    shell = cylinder_shell(R, 0.0, H, N, normals="outward")
    bottom = disc(R, 0.0, N, normal_up=False)
    top = disc(R, H, N, normal_up=True)
    closed = merge(shell, bottom, top)
    assert is_closed(closed)
    polygon_area = 0.5 * N * R**2 * math.sin(2 * math.pi / N)
    assert enclosed_volume(closed) == pytest.approx(polygon_area * H, rel=1e-12)
    # flipping all normals flips the sign; leaving out a cap opens the surface
    inward = merge(cylinder_shell(R, 0.0, H, N), disc(R, 0.0, N), disc(R, H, N, normal_up=False))
    assert is_closed(inward)
    assert enclosed_volume(inward) == pytest.approx(-polygon_area * H, rel=1e-12)
    assert not is_closed(merge(shell, bottom))
    # a cap with the wrong orientation is not consistently oriented
    assert not is_closed(merge(shell, bottom, disc(R, H, N, normal_up=False)))


def test_box_open_top_area_orientation_and_closing_lid() -> None:
    x0, x1, y0, y1, z0, z1 = -0.1, 0.2, 0.0, 0.05, 0.01, 0.04
    box = box_open_top(x0, x1, y0, y1, z0, z1, normals="outward")
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    assert box.shape == (10, 3, 3)
    assert surface_area(box) == pytest.approx(dx * dy + 2 * dz * (dx + dy), rel=1e-12)
    lid = rectangle(x0, x1, y0, y1, z1, normal_up=True)
    closed = merge(box, lid)
    assert is_closed(closed)
    assert enclosed_volume(closed) == pytest.approx(dx * dy * dz, rel=1e-12)
    # inward normals point at the box centre
    inward = box_open_top(x0, x1, y0, y1, z0, z1)
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2])
    to_centre = centre - inward.mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", triangle_normals(inward), to_centre) > 0)


def test_rectangle_and_general_quad() -> None:
    rect = rectangle(0.0, 0.3, -0.1, 0.1, 0.5)
    assert surface_area(rect) == pytest.approx(0.06)
    np.testing.assert_allclose(triangle_normals(rect), [[0, 0, 1], [0, 0, 1]])
    np.testing.assert_allclose(
        triangle_normals(rectangle(0.0, 0.3, -0.1, 0.1, 0.5, normal_up=False))[:, 2], -1.0
    )
    # a tilted parallelogram: area |a x b|
    p0 = np.array([0.0, 0.0, 0.0])
    a = np.array([0.2, 0.0, 0.1])
    b = np.array([0.05, 0.1, 0.0])
    q = quad(p0, p0 + a, p0 + a + b, p0 + b)
    assert surface_area(q) == pytest.approx(float(np.linalg.norm(np.cross(a, b))))
    expected = np.cross(a, b) / np.linalg.norm(np.cross(a, b))
    np.testing.assert_allclose(triangle_normals(q), [expected, expected])
    with pytest.raises(ValueError, match="coplanar"):
        quad(p0, p0 + a, p0 + a + b + np.array([0, 0, 0.05]), p0 + b)
    with pytest.raises(ValueError, match="degenerate"):
        quad(p0, p0, p0 + a, p0 + b)


def test_translate_and_rotate_preserve_area_and_move_points() -> None:
    tris = cylinder_shell(R, 0.0, H, 16, normals="outward")
    moved = translate(tris, [0.1, -0.2, 0.3])
    np.testing.assert_allclose(moved - tris, np.broadcast_to([0.1, -0.2, 0.3], tris.shape))
    rotated = rotate_z(rectangle(1.0, 2.0, 0.0, 0.5, 0.0), math.pi / 2)
    # (x, y) -> (-y, x): the rectangle now spans x in [-0.5, 0], y in [1, 2]
    assert rotated[..., 0].min() == pytest.approx(-0.5)
    assert rotated[..., 0].max() == pytest.approx(0.0, abs=1e-15)
    assert rotated[..., 1].min() == pytest.approx(1.0)
    assert rotated[..., 1].max() == pytest.approx(2.0)
    about = rotate_z(tris, 0.7, centre=(0.0, 0.0))
    assert surface_area(about) == pytest.approx(surface_area(tris), rel=1e-12)
    np.testing.assert_allclose(np.linalg.norm(about[..., :2], axis=-1), R, rtol=1e-12)
    # rotating about another centre moves that centre nowhere
    shifted = rotate_z(translate(tris, [1.0, 1.0, 0.0]), 1.1, centre=(1.0, 1.0))
    np.testing.assert_allclose(np.linalg.norm(shifted[..., :2] - 1.0, axis=-1), R, rtol=1e-12)


def test_ascii_round_trip_and_byte_stability(tmp_path: Path) -> None:
    tris = merge(cylinder_shell(R, 0.0, H, N), disc(R, 0.0, N))
    path_a, path_b = tmp_path / "a.stl", tmp_path / "sub" / "b.stl"
    write_stl_ascii(path_a, tris, name="cell_wall")
    write_stl_ascii(path_b, tris.copy(), name="cell_wall")
    assert path_a.read_bytes() == path_b.read_bytes()
    mesh = read_stl(path_a)
    assert mesh.name == "cell_wall"
    np.testing.assert_allclose(mesh.triangles, tris, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(mesh.normals, triangle_normals(tris), atol=1e-10)
    first_lines = path_a.read_text().splitlines()[:3]
    assert first_lines[0] == "solid cell_wall"
    assert first_lines[1].startswith("  facet normal ")
    assert first_lines[2] == "    outer loop"


def test_binary_round_trip_and_byte_stability(tmp_path: Path) -> None:
    tris = box_open_top(0.0, 0.1, 0.0, 0.2, 0.0, 0.05)
    path_a, path_b = tmp_path / "a.stl", tmp_path / "b.stl"
    write_stl_binary(path_a, tris, name="box")
    write_stl_binary(path_b, tris, name="box")
    data = path_a.read_bytes()
    assert data == path_b.read_bytes()
    assert len(data) == 84 + 50 * len(tris)
    assert struct.unpack_from("<I", data, 80)[0] == len(tris)
    mesh = read_stl(path_a)
    assert mesh.name == "box"
    np.testing.assert_allclose(mesh.triangles, tris, rtol=1e-7, atol=1e-9)  # float32
    np.testing.assert_allclose(mesh.normals, triangle_normals(tris), atol=1e-7)


def test_negative_zero_does_not_change_the_file(tmp_path: Path) -> None:
    tris = rectangle(0.0, 1.0, 0.0, 1.0, 0.0)
    write_stl_ascii(tmp_path / "a.stl", tris)
    negative_zeros = np.where(tris == 0, -0.0, tris)
    assert np.signbit(negative_zeros).any()
    write_stl_ascii(tmp_path / "b.stl", negative_zeros)
    assert b"-0.0" not in (tmp_path / "b.stl").read_bytes()
    assert (tmp_path / "a.stl").read_bytes() == (tmp_path / "b.stl").read_bytes()


def test_binary_header_starting_with_solid_is_read_as_binary(tmp_path: Path) -> None:
    tris = rectangle(0.0, 1.0, 0.0, 2.0, 0.5)
    path = tmp_path / "s.stl"
    write_stl_binary(path, tris)
    data = bytearray(path.read_bytes())
    data[:80] = b"solid exported by another tool".ljust(80, b" ")
    path.write_bytes(bytes(data))
    np.testing.assert_allclose(read_stl(path).triangles, tris)


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        (
            "solid x\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n",
            "unexpected end of file, expected 'vertex'",
        ),
        (
            "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 zero\n"
            "vertex 0 1 0\nendloop\nendfacet\nendsolid x\n",
            r":5: expected three finite numbers after 'vertex'",
        ),
        (
            "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
            "endloop\nendfacet\nendsolid x\n",
            r":6: expected 'vertex', found 'endloop'",
        ),
        ("solid x\nfacet normal 0 0 1\n", "unexpected end of file, expected 'outer loop'"),
        ("hello world\n", "not an ASCII STL"),
    ],
)
def test_malformed_ascii_names_the_file(tmp_path: Path, content: str, fragment: str) -> None:
    path = tmp_path / "broken.stl"
    path.write_text(content)
    with pytest.raises(StlFormatError, match=fragment) as info:
        read_stl(path)
    assert "broken.stl" in str(info.value)


def test_truncated_binary_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "cut.stl"
    write_stl_binary(path, disc(R, 0.0, 12))
    path.write_bytes(path.read_bytes()[:-7])
    with pytest.raises(StlFormatError, match=r"cut\.stl.*12 facets") as info:
        read_stl(path)
    assert "bytes" in str(info.value)


def test_bad_arguments() -> None:
    with pytest.raises(ValueError, match="n_segments"):
        cylinder_shell(R, 0.0, H, 2)
    with pytest.raises(ValueError, match="z0 < z1"):
        cylinder_shell(R, H, 0.0, 8)
    with pytest.raises(ValueError, match="normals"):
        cylinder_shell(R, 0.0, H, 8, normals="up")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="r_in < r_out"):
        annulus(R, R, 0.0, 8)
    with pytest.raises(ValueError, match="radius"):
        disc(-R, 0.0, 8)
    with pytest.raises(ValueError, match="name"):
        write_stl_ascii(Path("unused.stl"), disc(R, 0.0, 8), name="two words")
    with pytest.raises(FileNotFoundError, match=r"missing\.stl"):
        read_stl(Path("/nonexistent/missing.stl"))
