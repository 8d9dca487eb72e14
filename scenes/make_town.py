#!/usr/bin/env python3
"""Writes scenes/town.json (issue 32): a town on a generated fractal terrain — 1 600 buildings on
a grid of 40 m blocks and 8 000 trees along its streets and in the woods around it, all instanced
from a few level-of-detail groups and placed on the ground ("onGround"), with four cameras along
a flight over it. Seeded: the same file every run. Run once; the output is committed.

    python3 scenes/make_town.py
"""
import json
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))
FLOOR = 3.2
BLOCK = 40.0
SIDE = 40  # blocks a side: 1.6 km of town


def quad(mesh, o, u, v, color):
    """A quad with its own four vertices: corner o, edges u and v (front: u x v)."""
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    length = math.sqrt(sum(x * x for x in n))
    n = [x / length for x in n]
    base = len(mesh["positions"]) // 3
    for p in (o, [o[i] + u[i] for i in range(3)], [o[i] + u[i] + v[i] for i in range(3)],
              [o[i] + v[i] for i in range(3)]):
        mesh["positions"] += [round(x, 2) for x in p]
        mesh["normals"] += [int(round(x)) for x in n]
        mesh["colors"] += color + [1]
    mesh["indices"] += [base, base + 1, base + 2, base, base + 2, base + 3]


def building(width, depth, floors, columns, wall):
    """Walls of wall strips and window quads (each window its own quad), and a flat roof."""
    del columns  # (ribbon windows: one band of glass a floor)
    mesh = {"positions": [], "normals": [], "colors": [], "indices": []}
    glass = [0.12, 0.15, 0.2]
    height = floors * FLOOR
    x0, z0 = -width / 2, -depth / 2
    walls = [([x0, 0, -z0], [1, 0, 0], width), ([-x0, 0, -z0], [0, 0, -1], depth),
             ([-x0, 0, z0], [-1, 0, 0], width), ([x0, 0, z0], [0, 0, 1], depth)]
    for origin, along, length in walls:
        xs = [0, length]
        ys = [0] + [f * FLOOR + k for f in range(floors) for k in (0.9, 2.6)] + [height]
        for i in range(len(xs) - 1):
            for j in range(len(ys) - 1):
                o = [origin[k] + along[k] * xs[i] + (ys[j] if k == 1 else 0) for k in range(3)]
                quad(mesh, o, [a * (xs[i + 1] - xs[i]) for a in along], [0, ys[j + 1] - ys[j], 0],
                     glass if j % 2 else wall)
    quad(mesh, [x0, height, -z0], [width, 0, 0], [0, 0, -depth], [c * 0.8 for c in wall])
    return mesh


def main():
    rng = random.Random(32)
    lod_groups = {}
    kinds = []
    for k in range(6):
        width, depth, floors = 14 + 2 * (k % 3), 12 + 3 * (k % 2), 3 + 3 * k
        wall = [round(0.55 + 0.06 * (k % 3), 2), 0.52, round(0.46 + 0.05 * (k % 2), 2)]
        # From afar the walls' average: a band of glass (1.7 of every 3.2 m) and wall.
        far = [round(0.47 * c + 0.53 * g, 3) for c, g in zip(wall, [0.12, 0.15, 0.2])]
        name = f"building-{k}"
        lod_groups[name] = {"fade": 20, "levels": [
            {"to": 350, "mesh": building(width, depth, floors, 3 + k % 3, wall)},
            {"to": 4000, "primitive": "box", "size": [width, floors * FLOOR, depth], "color": far,
             "transform": {"translate": [0, floors * FLOOR / 2, 0]}}]}
        kinds.append((name, width, depth))
    for k, leaves in enumerate([[0.18, 0.42, 0.14], [0.24, 0.46, 0.16]]):
        crown = {"translate": [0, 4.6, 0]}
        lod_groups[f"tree-{k}"] = {"fade": 12, "levels": [
            {"to": 120, "primitive": "sphere", "radius": 2.4, "segments": 18, "rings": 10,
             "color": leaves, "transform": crown},
            {"to": 450, "primitive": "sphere", "radius": 2.4, "segments": 8, "rings": 5,
             "color": leaves, "transform": crown},
            {"to": 1400, "primitive": "sphere", "radius": 2.4, "segments": 4, "rings": 2,
             "color": leaves, "transform": crown}]}

    extent = SIDE * BLOCK
    placements = {name: [] for name in lod_groups}
    footprints = {}
    for bx in range(SIDE):
        for bz in range(SIDE):
            x = (bx + 0.5) * BLOCK - extent / 2
            z = (bz + 0.5) * BLOCK - extent / 2
            # Taller towards the centre of town.
            centre = 1 - min(1, math.hypot(x, z) / (extent / 2))
            k = min(5, int(rng.random() * 3 + centre * 4))
            turn = rng.choice([0, 90, 180, 270])
            name, width, depth = kinds[k]
            placements[name].append([round(x), 0, round(z), turn])
            half = (width if turn % 180 == 0 else depth) / 2 + 2, (depth if turn % 180 == 0 else width) / 2 + 2
            footprints[(bx, bz)] = (x, z, half)
    trees = 0
    while trees < 8000:
        # Two thirds in the town's streets, the rest in woods around it.
        spread = extent / 2 if trees < 5000 else extent * 1.2
        x, z = rng.uniform(-spread, spread), rng.uniform(-spread, spread)
        bx, bz = int((x + extent / 2) // BLOCK), int((z + extent / 2) // BLOCK)
        if (bx, bz) in footprints:
            cx, cz, (hw, hd) = footprints[(bx, bz)]
            if abs(x - cx) < hw and abs(z - cz) < hd:
                continue
        placements[f"tree-{rng.randrange(2)}"].append(
            [round(x, 1), 0, round(z, 1), rng.randrange(360), round(rng.uniform(0.8, 1.3), 2)])
        trees += 1

    scene = {
        "synthvis": 1,
        "description": "A town on generated terrain (issue 32): 1 600 instanced buildings (six kinds: walls with "
                       "a band of windows a floor near, boxes far) and 8 000 trees (two kinds, three levels) on the "
                       "ground, every level switch dissolving; four cameras along a flight over it. Written by "
                       "scenes/make_town.py.",
        "background": [0.58, 0.68, 0.82],
        "cameras": [
            {"position": [-1500, 260, 1500], "target": [0, 0, 0], "yfov": 55, "near": 1, "far": 9000},
            {"position": [-700, 140, 700], "target": [200, 20, -200], "yfov": 55, "near": 1, "far": 9000},
            {"position": [-150, 70, 160], "target": [300, 30, -250], "yfov": 55, "near": 1, "far": 9000},
            {"position": [400, 120, -300], "target": [1400, 0, -1600], "yfov": 55, "near": 1, "far": 9000}],
        "light": {"direction": [0.45, -0.7, 0.4], "color": [1, 0.96, 0.9], "ambient": 0.35},
        "fog": {"color": [0.58, 0.68, 0.82], "beta": 0.00025},
        "materials": [{"name": "ground", "phong": True}],
        "terrain": [{"name": "hills", "generate": {"size": 1025, "spacing": 10, "relief": 90, "seed": 32},
                     "material": "ground",
                     "ramp": [[-100, [0.28, 0.36, 0.22]], [60, [0.36, 0.42, 0.26]],
                              [200, [0.5, 0.48, 0.4]]]}],
        "lodGroups": lod_groups,
        "objects": [{"name": name, "lod": name, "onGround": True, "at": at}
                    for name, at in placements.items()],
    }
    with open(os.path.join(HERE, "town.json"), "w") as f:
        json.dump(scene, f, separators=(",", ":"))
        f.write("\n")


if __name__ == "__main__":
    main()
