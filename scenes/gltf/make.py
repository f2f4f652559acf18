#!/usr/bin/env python3
"""Writes pavilion.glb beside this script with trimesh (pip install trimesh): a glTF
2.0 scene made here, free of third-party terms, to show and test glTF loading: a floor, eight
columns that share one mesh, a ring of twelve tori that share another (so each is stored once
and placed by instances), and a sphere in the middle, with PBR base colours and metallic
factors. It has no lights and no camera: `fisheye render` frames it, lights it with a
headlight and a sun, and exposes it automatically.

    target/python-venv/bin/python scenes/gltf/make.py
"""
import math
import os

import trimesh

HERE = os.path.dirname(os.path.abspath(__file__))


def coloured(mesh, rgb, metallic=0.0, roughness=0.6):
    material = trimesh.visual.material.PBRMaterial(
        baseColorFactor=[*rgb, 1.0], metallicFactor=metallic, roughnessFactor=roughness
    )
    mesh.visual = trimesh.visual.TextureVisuals(material=material)
    return mesh


def place(scene, mesh, name, transforms):
    """One mesh `name`, placed by one node per transform (the glTF shares it)."""
    scene.add_geometry(mesh, geom_name=name, node_name=f"{name}-0", transform=transforms[0])
    for k, transform in enumerate(transforms[1:], 1):
        scene.graph.update(frame_to=f"{name}-{k}", frame_from=scene.graph.base_frame, matrix=transform, geometry=name)


def main():
    scene = trimesh.Scene()
    floor = coloured(trimesh.creation.box(extents=(8.0, 0.2, 8.0)), (0.55, 0.5, 0.45))
    scene.add_geometry(floor, geom_name="floor", transform=trimesh.transformations.translation_matrix((0, -0.1, 0)))
    column = coloured(trimesh.creation.cylinder(radius=0.18, height=2.4, sections=24), (0.85, 0.82, 0.75))
    # trimesh's cylinder stands along z: turn it to y, then place it on a circle.
    upright = trimesh.transformations.rotation_matrix(-math.pi / 2, (1, 0, 0))
    at = trimesh.transformations.translation_matrix
    turn = trimesh.transformations.rotation_matrix
    angles = [2 * math.pi * k / 8 for k in range(8)]
    place(scene, column, "column", [at((3.0 * math.cos(a), 1.2, 3.0 * math.sin(a))) @ upright for a in angles])
    torus = coloured(trimesh.creation.torus(major_radius=0.3, minor_radius=0.08, major_sections=32, minor_sections=12),
                     (0.9, 0.55, 0.2), metallic=1.0, roughness=0.2)
    angles = [2 * math.pi * k / 12 for k in range(12)]
    place(scene, torus, "torus", [at((1.8 * math.cos(a), 0.4, 1.8 * math.sin(a))) @ turn(a, (0, 1, 0)) for a in angles])
    ball = coloured(trimesh.creation.icosphere(subdivisions=3, radius=0.7), (0.3, 0.45, 0.8))
    scene.add_geometry(ball, geom_name="ball", transform=at((0, 0.7, 0)))
    path = os.path.join(HERE, "pavilion.glb")
    scene.export(path)
    print(f"wrote {path}: {os.path.getsize(path)} bytes")


if __name__ == "__main__":
    main()
