#!/usr/bin/env python3
"""Compares the frames a split run wrote in pieces (`[output] gather = "never"`) with the
gathered frames of the same run in one process. Usage: pieces_check.py ONE SPLIT FRAMES.
CSV pieces, joined and sorted by id, are the gathered frame's lines; the VTK pieces that
`particlesNNNNNN.pvtu` lists, read with meshio and joined, are the gathered `.vtu`; the
contact pieces are the gathered network; the `.pvd` collections list the `.pvtu`/`.pvtp`."""
import glob, os, sys, xml.etree.ElementTree as ET
import meshio, numpy as np

one, split, frames = sys.argv[1], sys.argv[2], int(sys.argv[3])


def lines(path):
    with open(path) as f:
        return f.read().splitlines()


def count_of(path, attribute):
    """The number a VTK XML file's header gives as `attribute` (NumberOfPoints, ...)."""
    with open(path, "rb") as f:
        head = f.read().split(b"<AppendedData")[0].decode()
    return int(head.split(f'{attribute}="')[1].split('"')[0])


def pieces(pattern):
    found = sorted(glob.glob(os.path.join(split, pattern)))
    assert found, f"no pieces {pattern}"
    return found


for k in range(frames + 1):
    # CSV: the same header, the same rows once sorted by id (the gathered frame is in id order).
    whole = lines(f"{one}/particles{k:06d}.csv")
    header, rows = None, []
    for p in pieces(f"particles{k:06d}_*.csv"):
        text = lines(p)
        assert header in (None, text[0]), (p, text[0], header)
        header = text[0]
        rows += text[1:]
    assert header == whole[0], (header, whole[0])
    at = header.split(",").index("id")
    rows.sort(key=lambda r: int(r.split(",")[at]))
    assert rows == whole[1:], f"frame {k}: the CSV pieces differ from the gathered frame"
    # VTK: the pieces the .pvtu lists, joined.
    listed = ET.parse(f"{split}/particles{k:06d}.pvtu").getroot()
    sources = [e.get("Source") for e in listed.iter("Piece")]
    assert len(sources) == len(pieces(f"particles{k:06d}_*.vtu")), sources
    # (meshio cannot read a file of no points: such a piece is counted, not read.)
    sizes = [count_of(f"{split}/{s}", "NumberOfPoints") for s in sources]
    parts = [meshio.read(f"{split}/{s}") for s, n in zip(sources, sizes) if n > 0]
    if count_of(f"{one}/particles{k:06d}.vtu", "NumberOfPoints") == 0:
        assert sum(sizes) == 0, sizes
    else:
        ref = meshio.read(f"{one}/particles{k:06d}.vtu")
        ids = np.concatenate([m.point_data["id"].reshape(-1) for m in parts])
        order = np.argsort(ids)
        assert np.array_equal(ids[order], ref.point_data["id"].reshape(-1)), f"frame {k}: ids"
        points = np.concatenate([m.points for m in parts])[order]
        assert np.array_equal(points, ref.points), f"frame {k}: points"
        for name, values in ref.point_data.items():
            joined = np.concatenate([m.point_data[name] for m in parts])[order]
            assert np.array_equal(joined, values), f"frame {k}: {name}"
        declared = {e.get("Name") for e in listed.iter("PDataArray")}
        assert set(ref.point_data) <= declared, (declared, set(ref.point_data))
    # Contacts: the pieces are the gathered network; the .pvtp lists as many lines.
    whole = lines(f"{one}/contacts{k:06d}.csv")
    rows = [r for p in pieces(f"contacts{k:06d}_*.csv") for r in lines(p)[1:]]
    assert sorted(rows) == sorted(whole[1:]), f"frame {k}: contact pieces"
    listed = ET.parse(f"{split}/contacts{k:06d}.pvtp").getroot()
    count = 0
    for s in (e.get("Source") for e in listed.iter("Piece")):
        count += count_of(f"{split}/{s}", "NumberOfLines")
    assert count == len(whole) - 1, (count, len(whole) - 1)

for stem, ext in (("particles", "pvtu"), ("contacts", "pvtp")):
    listed = ET.parse(f"{split}/{stem}.pvd").getroot()
    files = [e.get("file") for e in listed.iter("DataSet")]
    assert files == [f"{stem}{k:06d}.{ext}" for k in range(frames + 1)], files
print(f"{frames + 1} frames: pieces = gathered")
