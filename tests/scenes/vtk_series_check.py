"""Reads a conform run's ParaView series back with meshio and checks it against the run's own
PLY frames, metrics.csv and summary.json, independently of how conform wrote it.

Usage: /usr/bin/python3 vtk_series_check.py RUN_DIR [--prestress PA] [--gap]

Exits 0 when every check holds, 1 with the failed checks on stdout. --prestress: the scene's
isotropic pre-stress, which the membrane's principal stresses must equal in the first frame
(the body at its bind pose, unstrained). --gap: the series has a gap, 0 in the first frame
(no wound yet) and open (> 0) in the last.
"""

import csv
import json
import os
import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np

problems = []


def check(ok, message):
    if not ok:
        problems.append(message)
    return ok


class Ply:
    """A PLY frame of conform (binary little-endian, triangles, io::write_mesh): read here with
    numpy, since meshio 7's binary PLY reader takes one value of each face property for all."""

    def __init__(self, path):
        with open(path, "rb") as f:
            data = f.read()
        end = data.index(b"end_header\n") + len(b"end_header\n")
        header = data[:end].decode().splitlines()
        assert header[1] == "format binary_little_endian 1.0", header[1]
        types = {"double": "<f8", "float": "<f4", "int": "<i4", "uint": "<u4", "uchar": "u1"}
        elements, current = [], None
        for line in header:
            words = line.split()
            if words[0] == "element":
                current = (words[1], int(words[2]), [])
                elements.append(current)
            elif words[0] == "property" and words[1] == "list":
                current[2].extend([("count", "u1"), (words[4], "<i4", (3,))])
            elif words[0] == "property":
                current[2].append((words[2], types[words[1]]))
        offset = end
        self.element = {}
        for name, count, dtype in elements:
            self.element[name] = np.frombuffer(data, dtype=np.dtype(dtype), count=count,
                                               offset=offset)
            offset += count * np.dtype(dtype).itemsize
        assert offset == len(data), f"{path}: {len(data) - offset} bytes left over"
        v, f = self.element["vertex"], self.element["face"]
        assert np.all(f["count"] == 3), f"{path}: not triangles"
        self.points = np.column_stack([v["x"], v["y"], v["z"]])
        self.triangles = f["vertex_indices"]
        self.face = f


def read_pvd(path):
    root = ET.parse(path).getroot()
    check(root.tag == "VTKFile" and root.get("type") == "Collection", "pvd: not a Collection")
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def metrics_rows(run):
    with open(os.path.join(run, "metrics.csv"), newline="") as f:
        return list(csv.DictReader(f))


def check_frame(run, name, step, vtu, first):
    ply = Ply(os.path.join(run, "frames", f"{name}_{step:06d}.ply"))
    tag = f"frame {step}"
    corners = vtu.points[vtu.cells[0].data]
    check(len(vtu.cells[0].data) == len(ply.triangles),
          f"{tag}: {len(vtu.cells[0].data)} triangles, the PLY frame has {len(ply.triangles)}")
    if len(vtu.cells[0].data) == len(ply.triangles):
        check(np.allclose(corners, ply.points[ply.triangles], rtol=0, atol=1e-12),
              f"{tag}: the triangles' corners are not the PLY frame's")
    if "nx" in ply.element["vertex"].dtype.names:
        # Corner normals (an imported model's seams): the PLY frame splits each vertex once
        # per distinct normal and UV; the .vtu keeps one point per vertex.
        check(len(vtu.points) <= len(ply.points) and
              set(map(tuple, vtu.points)) == set(map(tuple, ply.points)),
              f"{tag}: the points are not the PLY frame's split vertices")
    else:
        check(len(vtu.points) == len(ply.points),
              f"{tag}: {len(vtu.points)} points, the PLY frame has {len(ply.points)}")
        check(len(vtu.points) == len(ply.points) and
              np.allclose(vtu.points, ply.points, rtol=0, atol=1e-12), f"{tag}: points differ")
    check(vtu.cells[0].type == "triangle", f"{tag}: cells are not triangles")
    for field, prop in (("face_tag", "surface"), ("face_op", "op"), ("face_edit", "edit")):
        # A mesh without tags writes none: every face is then the model's skin (0).
        expected = ply.face[prop] if prop in ply.face.dtype.names else np.zeros(len(ply.face))
        check(np.array_equal(np.asarray(vtu.cell_data[field][0]).ravel(), expected),
              f"{tag}: {field} is not the PLY's {prop}")
    for key, values in list(vtu.point_data.items()) + list(vtu.cell_data.items()):
        values = np.concatenate(values) if isinstance(values, list) else values
        check(np.all(np.isfinite(np.asarray(values, dtype=float))), f"{tag}: {key} is not finite")
    # The displacement is from the bind pose: between two frames it changes as the positions
    # do, for the vertices both frames have (an edit only appends vertices).
    if first is not None:
        n = len(first.points)
        moved = vtu.point_data["displacement"][:n] - first.point_data["displacement"]
        check(np.allclose(moved, vtu.points[:n] - first.points, rtol=0, atol=1e-9),
              f"{tag}: displacement - first frame's != position - first frame's")
    return ply


def main(argv):
    run = argv[1]
    prestress = float(argv[argv.index("--prestress") + 1]) if "--prestress" in argv else None
    with open(os.path.join(run, "summary.json")) as f:
        summary = json.load(f)
    vtk = summary["vtk"]
    check(vtk.get("pvd") == "vtk/series.pvd", f"summary vtk.pvd is {vtk.get('pvd')}")
    check(not summary["failures"], f"summary failures: {summary['failures']}")
    series = read_pvd(os.path.join(run, "vtk", "series.pvd"))
    times = [t for t, _ in series]
    check(len(series) >= 2, f"{len(series)} frames in the series")
    check(all(b > a for a, b in zip(times, times[1:])), f"times not increasing: {times}")
    check(["vtk/" + f for _, f in series] == vtk["files"], "pvd files are not summary's vtk.files")
    name = vtk["frames_of"]
    steps = sorted(int(f[len(name) + 1:-4]) for f in os.listdir(os.path.join(run, "frames"))
                   if f.startswith(name + "_") and f.endswith(".ply"))
    dt = summary["settings"]["physics"]["dt"]
    check(len(steps) == len(series), f"{len(series)} vtu files for {len(steps)} PLY frames")
    metric_times = [float(r["t"]) for r in metrics_rows(run)]
    metrics_every = summary["settings"]["outputs"].get("metrics_every", 1)
    first = None
    for (time, file), step in zip(series, steps):
        check(file == f"frame_{step:06d}.vtu", f"{file} is not step {step}'s")
        check(abs(time - step * dt) <= 1e-12 * max(1.0, time), f"{file}: time {time} != {step} dt")
        # metrics.csv writes t to 9 digits, on every metrics_every-th step and the last.
        if step % metrics_every == 0 or step == steps[-1]:
            check(step == 0 or any(abs(time - t) <= 1e-8 * max(1.0, time) for t in metric_times),
                  f"{file}: time {time} is not a metrics.csv time")
        vtu = meshio.read(os.path.join(run, "vtk", file))
        check_frame(run, name, step, vtu, first)
        if first is None:
            first = vtu
            if prestress is not None:
                s = vtu.point_data["principal_stress"]
                check(np.allclose(s, prestress, rtol=1e-3),
                      f"first frame's principal stresses {s.min()}..{s.max()}, not {prestress}")
    # The last frame's pieces: as many as the run counted at the end.
    pieces = set(int(p) for p in vtu.point_data["piece"] if p >= 0)
    counted = summary["metrics"].get("pieces")  # the scenes that edit the body count them
    check(counted is None or len(pieces) == counted,
          f"last frame has pieces {sorted(pieces)}, summary says {counted}")
    check(set(vtk["point_data"]) == set(vtu.point_data), "summary's point_data != the vtu's")
    if "--gap" in argv:
        check(not first.point_data["gap"].any(), "the first frame has a gap")
        check(vtu.point_data["gap"].max() > 0, "the last frame's gap is 0")
    for line in problems:
        print("FAIL:", line)
    print(f"checked {len(series)} frames, fields {sorted(vtu.point_data)}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
