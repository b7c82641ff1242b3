"""Every Python snippet of docs/python.md runs as written, in a folder
holding the files it names (a mesh with UVs, a groom file on it, three
maps and the animated Fox), so the page cannot drift from the package."""

import os
import pathlib
import re
import shutil
import struct
import zlib

import pytest

from conftest import MESHES, REPO

DOC = REPO / "docs" / "python.md"
FOX = REPO / "crates" / "pelage" / "assets" / "fox"


def snippets():
    return re.findall(r"```python\n(.*?)```", DOC.read_text(), re.S)


def grey_png(path, side=64):
    """A grey-scale PNG: a ramp left to right (values 0 to 255)."""
    rows = b"".join(b"\0" + bytes(int(255 * x / (side - 1)) for x in range(side)) for _ in range(side))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", side, side, 8, 0, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


@pytest.fixture()
def doc_folder(tmp_path):
    shutil.copy(MESHES / "blub_triangulated.obj", tmp_path / "model.obj")
    for name in FOX.iterdir():
        shutil.copy(name, tmp_path / name.name)
    for name in ["density.png", "back.png", "parting.png"]:
        grey_png(tmp_path / name)
    (tmp_path / "fur.toml").write_text(
        '[mesh]\npath = "model.obj"\n[roots]\ncount = 2000\n'
        "[guides]\ngenerate = { count = 50, length = 0.05 }\n"
    )
    here = os.getcwd()
    os.chdir(tmp_path)
    yield tmp_path
    os.chdir(here)


def test_the_page_has_snippets():
    assert len(snippets()) >= 2


@pytest.mark.parametrize("k", range(len(snippets())))
def test_each_snippet_of_the_python_page_runs(doc_folder, k):
    code = snippets()[k]
    exec(compile(code, f"{DOC.name} snippet {k + 1}", "exec"), {"__name__": "__doc_snippet__"})
