"""Issue 47's pixel budget: an image's size is checked against it before anything decodes it, in check,
render and report alike; a texture over it falls back with a note, and never loses the rest of a run."""

from __future__ import annotations

import json
import resource
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import pytest
from helpers.cli import run

TRAPEZOID = "v -1 0 0\nv 1 0 0\nv 0.5 1 0\nv -0.5 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"


def png_claiming(width: int, height: int) -> bytes:
    """A PNG signature and a valid IHDR chunk (CRC included) claiming ``width`` x ``height`` RGB, and an
    empty IEND: a header that promises far more pixels than the file holds."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IEND", b""))


@pytest.fixture
def two_meshes(tmp_path) -> Path:
    """``huge.obj`` whose map_Kd claims 100,000 x 100,000 pixels, and ``plain.obj`` beside it (no texture)."""
    (tmp_path / "huge.png").write_bytes(png_claiming(100_000, 100_000))
    (tmp_path / "huge.mtl").write_text("newmtl m\nmap_Kd huge.png\n")
    (tmp_path / "huge.obj").write_text("mtllib huge.mtl\nusemtl m\n" + TRAPEZOID)
    (tmp_path / "plain.obj").write_text(TRAPEZOID)
    return tmp_path


def test_a_header_of_a_second_library_is_read_and_its_size_refused(tmp_path, monkeypatch):
    from PIL import Image

    from affinity.loaders.imagesize import read_header
    from affinity.textures.decode import TextureUnusable, decode, why_not_decoded

    (tmp_path / "huge.png").write_bytes(png_claiming(100_000, 100_000))
    monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", None)  # Pillow's own bomb check would refuse to open it
    with Image.open(tmp_path / "huge.png") as image:  # Pillow reads the same header
        assert image.size == (100_000, 100_000)
    assert read_header(tmp_path / "huge.png").size == (100_000, 100_000)
    assert "over the decode budget" in why_not_decoded(str(tmp_path / "huge.png"))
    with pytest.raises(TextureUnusable, match="100000x100000 is over the decode budget"):
        decode(str(tmp_path / "huge.png"))
    Image.new("RGB", (64, 32), "red").save(tmp_path / "small.png")
    with pytest.raises(TextureUnusable, match="64x32 is over the decode budget of 1,000 pixels"):
        decode(str(tmp_path / "small.png"), budget=1000)
    assert decode(str(tmp_path / "small.png")).pixels.shape == (32, 64, 3)


def test_check_reads_the_texel_unit_from_the_header_and_says_why_not_c(two_meshes):
    result = run("check", "--no-cache", "--format", "json", str(two_meshes / "huge.obj"), str(two_meshes / "plain.obj"))
    assert result.returncode == 1, result.stderr
    assert "Traceback" not in result.stderr
    doc = json.loads(result.stdout)
    by_file = {Path(f["path"]).name: f for f in doc["findings"] if f["code"] == "Q101"}
    huge, plain = by_file["huge.obj"], by_file["plain.obj"]
    assert huge["unit"] == "texels" and "shift" not in huge  # the texel reading, at the header's size
    assert huge["value"] == pytest.approx(plain["value"] / 1024 * 100_000, rel=1e-9)
    assert "huge.png" in huge["message"] and "over the decode budget" in huge["message"]
    assert "texels of its 100000x100000 header" in huge["message"]


def test_render_falls_back_to_the_checker_with_a_warning(two_meshes, tmp_path):
    result = run("render", str(two_meshes / "huge.obj"), "-o", str(tmp_path / "out.png"), "--size", "64x48")
    assert result.returncode == 0, result.stderr
    assert "over the decode budget" in result.stderr and "checker" in result.stderr
    assert (tmp_path / "out.png").exists()


@pytest.mark.slow  # a report in a process of its own under a memory limit
def test_one_huge_texture_never_loses_the_other_mesh_of_a_report(two_meshes, tmp_path):
    """The report of both meshes is written, each mesh in it; the huge one's close-ups draw the line pattern
    and say why, and the process stays far from what decoding 10^10 pixels would take."""
    out = tmp_path / "report.html"
    script = ("import resource, runpy, sys; sys.argv = ['affinity'] + sys.argv[1:]; "
              "resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30)); "
              "runpy.run_module('affinity.cli', run_name='__main__')")
    result = subprocess.run([sys.executable, "-c", script, "report", "-q", "-o", str(out),
                             str(two_meshes / "huge.obj"), str(two_meshes / "plain.obj")],
                            capture_output=True, text=True)
    assert result.returncode in (0, 1), result.stderr
    assert "Traceback" not in result.stderr
    page = out.read_text()
    assert "huge.obj" in page and "plain.obj" in page
    assert "huge.png" in page and "over the decode budget" in page
    assert resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss < (2 << 20)  # KiB: under 2 GiB
