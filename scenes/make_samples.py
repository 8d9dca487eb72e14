#!/usr/bin/env python3
"""Writes the small sample assets in scenes/: pyramid.gltf (a vertex-coloured pyramid with its
buffer embedded as base64), house.obj + house.mtl, and crate.gltf (a textured box: a PNG of
planks embedded in the glTF, with a repeat sampler). Run once; the outputs are committed.

    python3 scenes/make_samples.py
"""
import base64
import json
import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(sum(x * x for x in a))
    return [x / n for x in a]


def make_pyramid():
    # Square base of side 1 on y = 0, apex at y = 0.9. Every face has its own vertices, so each
    # gets a flat normal and a colour of its own.
    base = [[-0.5, 0, 0.5], [0.5, 0, 0.5], [0.5, 0, -0.5], [-0.5, 0, -0.5]]
    apex = [0, 0.9, 0]
    colours = [[0.9, 0.2, 0.15, 1], [0.95, 0.75, 0.2, 1], [0.2, 0.6, 0.25, 1], [0.2, 0.35, 0.85, 1]]
    positions, normals, colors, indices = [], [], [], []
    for k in range(4):
        a, b = base[k], base[(k + 1) % 4]
        tri = [a, b, apex]  # counter-clockwise seen from outside
        n = unit(cross(sub(b, a), sub(apex, a)))
        for p in tri:
            indices.append(len(positions))
            positions.append(p)
            normals.append(n)
            colors.append(colours[k])
    # The base faces down: b0, b3, b2, b1 runs counter-clockwise seen from below.
    first = len(positions)
    for p in [base[0], base[3], base[2], base[1]]:
        positions.append(p)
        normals.append([0, -1, 0])
        colors.append([0.5, 0.5, 0.5, 1])
    indices += [first, first + 1, first + 2, first, first + 2, first + 3]

    blob = b"".join(struct.pack("<3f", *p) for p in positions)
    blob += b"".join(struct.pack("<3f", *n) for n in normals)
    blob += b"".join(struct.pack("<4f", *c) for c in colors)
    index_bytes = b"".join(struct.pack("<H", i) for i in indices)
    index_bytes += b"\0" * (-len(index_bytes) % 4)
    offsets = [0, 12 * len(positions), 24 * len(positions), 40 * len(positions)]
    blob += index_bytes
    n = len(positions)
    gltf = {
        "asset": {"version": "2.0", "generator": "synthvis scenes/make_samples.py"},
        "scene": 0,
        "scenes": [{"name": "pyramid", "nodes": [0]}],
        # The mesh sits under a node turned 45 degrees about Y, so loaders must apply node
        # transforms to show it corner-on.
        "nodes": [{"name": "pyramid", "mesh": 0,
                   "rotation": [0, math.sin(math.pi / 8), 0, math.cos(math.pi / 8)]}],
        "meshes": [{"name": "pyramid", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "COLOR_0": 2},
            "indices": 3, "material": 0, "mode": 4}]}],
        "materials": [{"name": "painted", "doubleSided": False,
                       "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1]}}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
             "min": [-0.5, 0, -0.5], "max": [0.5, 0.9, 0.5]},
            {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC4"},
            {"bufferView": 3, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": offsets[0], "byteLength": 12 * n, "target": 34962},
            {"buffer": 0, "byteOffset": offsets[1], "byteLength": 12 * n, "target": 34962},
            {"buffer": 0, "byteOffset": offsets[2], "byteLength": 16 * n, "target": 34962},
            {"buffer": 0, "byteOffset": offsets[3], "byteLength": 2 * len(indices), "target": 34963},
        ],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    }
    with open(os.path.join(HERE, "pyramid.gltf"), "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


def make_house():
    # Walls: a 2 x 1.5 x 2 box standing on y = 0; roof: a prism with its ridge along x at y = 2.4.
    v = [[-1, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1],
         [-1, 1.5, 1], [1, 1.5, 1], [1, 1.5, -1], [-1, 1.5, -1],
         [-1, 2.4, 0], [1, 2.4, 0]]
    slope = unit([0, 1, 0.9])
    normals = [[1, 0, 0], [-1, 0, 0], [0, 0, 1], [0, 0, -1], [0, -1, 0],
               [0, slope[1], slope[2]], [0, slope[1], -slope[2]]]
    # Faces as 1-based vertex indices, counter-clockwise from outside, with their normal's index.
    walls = [([1, 2, 6, 5], 3), ([2, 3, 7, 6], 1), ([3, 4, 8, 7], 4), ([4, 1, 5, 8], 2),
             ([1, 4, 3, 2], 5)]
    roof = [([5, 6, 10, 9], 6), ([7, 8, 9, 10], 7), ([6, 7, 10], 1), ([8, 5, 9], 2)]
    lines = ["# A small house: two materials, quads and triangles, per-face normals.",
             "# Written by scenes/make_samples.py.", "mtllib house.mtl", "o house"]
    lines += ["v {:g} {:g} {:g}".format(*p) for p in v]
    lines += ["vn {:.6f} {:.6f} {:.6f}".format(*n) for n in normals]
    for name, faces in (("walls", walls), ("roof", roof)):
        lines.append("usemtl " + name)
        for face, n in faces:
            lines.append("f " + " ".join("{}//{}".format(i, n) for i in face))
    with open(os.path.join(HERE, "house.obj"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(HERE, "house.mtl"), "w") as f:
        f.write("# Materials of house.obj (Kd is the base colour).\n"
                "newmtl walls\nKd 0.85 0.75 0.55\nd 1\nillum 1\n\n"
                "newmtl roof\nKd 0.60 0.12 0.08\nd 1\nillum 1\n")


def png_rgb(width, height, pixel):
    """An 8-bit RGB PNG of pixel(x, y) -> (r, g, b), as bytes (PNG 1.2: IHDR, one IDAT, IEND)."""
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    raw = b"".join(b"\x00" + bytes(c for x in range(width) for c in pixel(x, y))
                   for y in range(height))
    return (b"\x89PNG\r\n\x1a\n" +
            chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def make_crate():
    # A unit box (centred, on y = 0) with 24 vertices, uvs 0..1 per face, and a 64 x 64 texture
    # of four planks with dark frame and a cross brace; glTF v runs down the image.
    def planks(x, y):
        frame = x < 5 or x > 58 or y < 5 or y > 58
        brace = abs(x - y) < 4 or abs(x + y - 63) < 4
        if frame or brace:
            return (92, 60, 30)
        seam = (y % 16) in (0, 15)
        grain = int(12 * math.sin(x * 0.35 + (y // 16) * 1.7)) + ((x * 7 + y * 13) % 5)
        base = 60 if seam else 150 + grain
        return (base, int(base * 0.72), int(base * 0.42))
    image = png_rgb(64, 64, planks)
    faces = [  # normal, u axis, v axis (v down the image = -up on the face)
        ((0, 0, 1), (1, 0, 0), (0, -1, 0)), ((0, 0, -1), (-1, 0, 0), (0, -1, 0)),
        ((1, 0, 0), (0, 0, -1), (0, -1, 0)), ((-1, 0, 0), (0, 0, 1), (0, -1, 0)),
        ((0, 1, 0), (1, 0, 0), (0, 0, 1)), ((0, -1, 0), (1, 0, 0), (0, 0, -1))]
    pos, nrm, uv, idx = [], [], [], []
    for n, u, v in faces:
        base = len(pos)
        for cu, cv in ((0, 0), (1, 0), (1, 1), (0, 1)):
            p = [0.5 * n[i] + (cu - 0.5) * u[i] + (cv - 0.5) * v[i] for i in range(3)]
            p[1] += 0.5
            pos.append(p)
            nrm.append(list(n))
            uv.append([cu, cv])
        # Counter-clockwise seen from outside: (u, v) is left-handed on the face (v down).
        idx += [base, base + 2, base + 1, base, base + 3, base + 2]
    blob = b"".join(struct.pack("<3f", *p) for p in pos)
    blob += b"".join(struct.pack("<3f", *n) for n in nrm)
    blob += b"".join(struct.pack("<2f", *t) for t in uv)
    blob += b"".join(struct.pack("<H", i) for i in idx)
    n = len(pos)
    gltf = {
        "asset": {"version": "2.0", "generator": "synthvis scenes/make_samples.py"},
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "crate"}],
        "meshes": [{"name": "crate", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
            "indices": 3, "material": 0}]}],
        "materials": [{"name": "planks", "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0}, "metallicFactor": 0}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"wrapS": 10497, "wrapT": 10497}],
        "images": [{"name": "planks",
                    "uri": "data:image/png;base64," + base64.b64encode(image).decode()}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," +
                            base64.b64encode(blob).decode()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 12 * n},
            {"buffer": 0, "byteOffset": 12 * n, "byteLength": 12 * n},
            {"buffer": 0, "byteOffset": 24 * n, "byteLength": 8 * n},
            {"buffer": 0, "byteOffset": 32 * n, "byteLength": 2 * len(idx)}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
             "min": [-0.5, 0, -0.5], "max": [0.5, 1, 0.5]},
            {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": len(idx), "type": "SCALAR"}],
    }
    with open(os.path.join(HERE, "crate.gltf"), "w") as f:
        json.dump(gltf, f, indent=1)


if __name__ == "__main__":
    make_pyramid()
    make_house()
    make_crate()
