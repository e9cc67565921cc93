"""Image sizes read from headers by hand (affinity.loaders.imagesize), against files other libraries wrote:
Pillow (PNG, JPEG, TGA, BMP, TIFF, DDS), tifffile (tiled TIFF as .tx, BigTIFF, big-endian) and OpenEXR."""

from __future__ import annotations

import numpy as np
import pytest

from affinity.loaders.imagesize import ImageUnreadable, read_header

SIZE = (300, 123)  # width, height: not square, not a power of two


@pytest.mark.parametrize(
    "name, mode, options, kind",
    [
        ("t.png", "RGB", {}, "PNG"),
        ("t16.png", "I;16", {}, "PNG"),
        ("t.jpg", "RGB", {"progressive": True}, "JPEG"),
        ("t.tga", "RGBA", {"compression": "tga_rle"}, "TGA"),
        ("t.bmp", "RGB", {}, "BMP"),
        ("t.tif", "RGB", {"compression": "tiff_lzw"}, "TIFF"),
        ("t.dds", "RGBA", {}, "DDS"),
        ("t_dxt1.dds", "RGB", {"pixel_format": "DXT1"}, "DDS"),
    ],
)
def test_headers_of_files_pillow_writes(tmp_path, name, mode, options, kind):
    from PIL import Image

    path = tmp_path / name
    Image.new(mode, SIZE).save(path, **options)
    with Image.open(path) as image:
        assert image.size == SIZE  # Pillow agrees on what it wrote
    header = read_header(path)
    assert (header.size, header.format) == (SIZE, kind)


@pytest.mark.parametrize(
    "name, options",
    [
        ("tiled.tx", {"tile": (32, 32)}),
        ("big.tif", {"bigtiff": True}),
        ("motorola.tif", {"byteorder": ">"}),
        ("tiled_big.tx", {"tile": (64, 64), "bigtiff": True, "byteorder": ">"}),
    ],
)
def test_headers_of_tiff_files_tifffile_writes(tmp_path, name, options):
    tifffile = pytest.importorskip("tifffile")
    path = tmp_path / name
    tifffile.imwrite(path, np.zeros((SIZE[1], SIZE[0], 3), dtype=np.uint16), photometric="rgb", **options)
    with tifffile.TiffFile(path) as tif:
        assert tif.pages[0].shape[:2] == (SIZE[1], SIZE[0])
    assert read_header(path).size == SIZE


@pytest.mark.parametrize("window", [(0, 0), (-7, 20)])
def test_headers_of_exr_files_openexr_writes(tmp_path, window):
    OpenEXR = pytest.importorskip("OpenEXR")
    path = tmp_path / "t.exr"
    x_min, y_min = window
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage,
              "dataWindow": (np.array([x_min, y_min], dtype=np.int32),
                             np.array([x_min + SIZE[0] - 1, y_min + SIZE[1] - 1], dtype=np.int32)),
              "displayWindow": (np.array([0, 0], dtype=np.int32), np.array([SIZE[0] - 1, SIZE[1] - 1], dtype=np.int32))}
    with OpenEXR.File(header, {"RGB": np.zeros((SIZE[1], SIZE[0], 3), dtype=np.float32)}) as exr:
        exr.write(str(path))
    with OpenEXR.File(str(path)) as exr:
        assert exr.channels()["RGB"].pixels.shape[:2] == (SIZE[1], SIZE[0])
    header = read_header(path)
    assert (header.size, header.format) == (SIZE, "EXR")


def test_what_no_header_reader_accepts(tmp_path):
    (tmp_path / "pointer.png").write_text("version https://git-lfs.github.com/spec/v1\noid sha256:00\nsize 1\n")
    (tmp_path / "junk.exr").write_bytes(b"\x76\x2f\x31\x01" + b"\x02\x00\x00\x00" + b"x" * 300)
    (tmp_path / "cut.tif").write_bytes(b"II*\x00\x08\x00\x00\x00\x05\x00")
    (tmp_path / "cut.dds").write_bytes(b"DDS \x7c\x00")
    reasons = {}
    for name in ["pointer.png", "junk.exr", "cut.tif", "cut.dds", "missing.png"]:
        with pytest.raises(ImageUnreadable) as err:
            read_header(tmp_path / name)
        reasons[name] = str(err.value)
    assert reasons == {"pointer.png": "a Git LFS pointer", "junk.exr": "not a readable image",
                       "cut.tif": "not a readable image", "cut.dds": "not a readable image", "missing.png": "missing"}
