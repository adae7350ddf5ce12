"""Writes the 3MF test files of tests/wild by hand (3MF is a zip package of
XML parts; no exporter needed):

- colour_cubes.3mf: millimetres, Z up. A 20 mm cube coloured red by a base
  material (object-level pid/pindex), built at the origin; an assembly
  object whose component places a second 20 mm cube 40 mm along +X with
  one triangle's corners coloured by a colour group (red, green, blue),
  built 10 mm up; the build items have transforms.
- no_model.3mf: a package without a model part.
- bad_vertex.3mf: a triangle naming vertex 9 of a 3-vertex mesh.
- cycle.3mf: an object that is its own component.
- not_zip.3mf: text, not a package.

    python3 scripts/make_3mf_fixtures.py tests/wild
"""
import os
import sys
import zipfile

out = os.path.abspath(sys.argv[1])
CT = """<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
 <Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
 <Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>
</Types>"""
RELS = """<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
 <Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>"""


def cube(size, extra=""):
    s = size
    v = [(x, y, z) for z in (0, s) for y in (0, s) for x in (0, s)]
    faces = [(0, 2, 1), (1, 2, 3), (4, 5, 6), (5, 7, 6), (0, 1, 4), (1, 5, 4),
             (2, 6, 3), (3, 6, 7), (0, 4, 2), (2, 4, 6), (1, 3, 5), (3, 7, 5)]
    vs = "".join(f'<vertex x="{x}" y="{y}" z="{z}"/>' for x, y, z in v)
    ts = []
    for k, (a, b, c) in enumerate(faces):
        attrs = extra if k == 4 else ""
        ts.append(f'<triangle v1="{a}" v2="{b}" v3="{c}"{attrs}/>')
    return f"<mesh><vertices>{vs}</vertices><triangles>{''.join(ts)}</triangles></mesh>"


def model(resources, build, unit="millimeter"):
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<model unit="{unit}" xml:lang="en-US" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02" xmlns:m="http://schemas.microsoft.com/3dmanufacturing/material/2015/02">
 <resources>{resources}</resources>
 <build>{build}</build>
</model>"""


def package(name, model_xml, with_model=True):
    with zipfile.ZipFile(os.path.join(out, name), "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("[Content_Types].xml", CT)
        z.writestr("_rels/.rels", RELS)
        if with_model:
            z.writestr("3D/3dmodel.model", model_xml)


GROUP = ' pid="2" p1="0" p2="1" p3="2"'
package("colour_cubes.3mf", model(
    '<basematerials id="1"><base name="Red" displaycolor="#FF0000"/><base name="White" displaycolor="#FFFFFF"/></basematerials>'
    '<m:colorgroup id="2"><m:color color="#FF0000"/><m:color color="#00FF00"/><m:color color="#0000FFFF"/></m:colorgroup>'
    f'<object id="3" type="model" pid="1" pindex="0">{cube(20)}</object>'
    f'<object id="4" type="model" pid="1" pindex="1">{cube(20, GROUP)}</object>'
    '<object id="5" type="model"><components><component objectid="4" transform="1 0 0 0 1 0 0 0 1 40 0 0"/></components></object>',
    '<item objectid="3"/><item objectid="5" transform="1 0 0 0 1 0 0 0 1 0 0 10"/>'))
package("no_model.3mf", "", with_model=False)
package("bad_vertex.3mf", model(
    '<object id="1" type="model"><mesh><vertices><vertex x="0" y="0" z="0"/><vertex x="1" y="0" z="0"/>'
    '<vertex x="0" y="1" z="0"/></vertices><triangles><triangle v1="0" v2="1" v3="9"/></triangles></mesh></object>',
    '<item objectid="1"/>'))
package("cycle.3mf", model(
    '<object id="1" type="model"><components><component objectid="1"/></components></object>',
    '<item objectid="1"/>'))
with open(os.path.join(out, "not_zip.3mf"), "w") as f:
    f.write("solid not a 3mf package\n")
