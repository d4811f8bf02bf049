"""A conform run's kept frames as a ParaView time series, written with meshio.

conform run (outputs.vtk) runs this with Debian's /usr/bin/python3 as

    vtk_series.py STAGING OUT

STAGING holds manifest.json and one text PLY per kept frame, written by conform
(scenes/render/vtk_series.cpp): the vertices' positions and fields as vertex properties, the
faces' tags as face properties. manifest.json says which properties make which field:

    {"frames": [{"file": "frame_000030.ply", "vtu": "frame_000030.vtu", "time": 0.5}, ...],
     "point_data": [{"name": "displacement", "properties": ["displacement_x", ...]}, ...],
     "cell_data": [{"name": "face_tag", "property": "surface"}, ...]}

OUT (created) receives one .vtu per frame (meshio's VTK XML writer) and series.pvd, the index
ParaView opens, with each frame's time in seconds (xml.etree.ElementTree).

Exit status: 0 written; 3 meshio is not installed (scripts/deps.sh installs python3-meshio);
anything else a failure, with the reason on stderr.
"""

import json
import os
import sys
import xml.etree.ElementTree as ET

MESHIO_MISSING = 3


def point_field(mesh, field, ply_name):
    """The named point field: one PLY property (a scalar) or several (a vector's components)."""
    columns = []
    for prop in field["properties"]:
        if prop not in mesh.point_data:
            raise ValueError(f"{ply_name}: vertex property '{prop}' is missing")
        columns.append(mesh.point_data[prop])
    if len(columns) == 1:
        return columns[0]
    import numpy

    return numpy.column_stack(columns)


def cell_field(mesh, field, ply_name):
    """The named cell field: one PLY face property, per triangle."""
    prop = field["property"]
    if prop not in mesh.cell_data:
        raise ValueError(f"{ply_name}: face property '{prop}' is missing")
    return mesh.cell_data[prop]


def convert_frame(meshio, staging, out, frame, manifest):
    """Reads one staging PLY and writes its .vtu with the manifest's fields."""
    ply = os.path.join(staging, frame["file"])
    mesh = meshio.read(ply, file_format="ply")
    if len(mesh.cells) != 1 or mesh.cells[0].type != "triangle":
        raise ValueError(f"{frame['file']}: expected one block of triangles")
    point_data = {f["name"]: point_field(mesh, f, frame["file"]) for f in manifest["point_data"]}
    cell_data = {f["name"]: cell_field(mesh, f, frame["file"]) for f in manifest["cell_data"]}
    result = meshio.Mesh(mesh.points, mesh.cells, point_data=point_data, cell_data=cell_data)
    meshio.write(os.path.join(out, frame["vtu"]), result, file_format="vtu")


def write_pvd(path, frames):
    """series.pvd: VTK's collection file, one DataSet per frame at its time."""
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    collection = ET.SubElement(root, "Collection")
    for frame in frames:
        ET.SubElement(collection, "DataSet", timestep=repr(float(frame["time"])), group="",
                      part="0", file=frame["vtu"])
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)


def main(argv):
    if len(argv) != 3:
        print("usage: vtk_series.py STAGING OUT", file=sys.stderr)
        return 2
    staging, out = argv[1], argv[2]
    try:
        import meshio
    except ImportError as error:
        print(f"meshio is not installed ({error}); scripts/deps.sh installs python3-meshio",
              file=sys.stderr)
        return MESHIO_MISSING
    with open(os.path.join(staging, "manifest.json"), encoding="utf-8") as f:
        manifest = json.load(f)
    os.makedirs(out, exist_ok=True)
    for frame in manifest["frames"]:
        convert_frame(meshio, staging, out, frame, manifest)
    write_pvd(os.path.join(out, "series.pvd"), manifest["frames"])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
