#!/usr/bin/env python3
"""Writes round three's hostile inputs (docs/hardening-memory.md, "Round three") into a
folder: small glTF and scene files that declare far more than they hold. Each is
under 64 KB. `sh scripts/hostile-memory.sh` renders every one and reports its peak
memory and time.

    python3 scripts/hostile-round3.py FOLDER
"""
import base64, io, json, struct, sys, zlib
from pathlib import Path


def png(width, height):
    """A 1-bit grey PNG of one colour: a few KB however large it declares itself."""
    row = b"\x00" + b"\xff" * ((width + 7) // 8)
    data = zlib.compress(row * height, 9)
    chunk = lambda kind, body: struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    header = struct.pack(">IIBBBBB", width, height, 1, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", data) + chunk(b"IEND", b"")


def data_uri(raw):
    return "data:application/octet-stream;base64," + base64.b64encode(raw).decode()


def sparse_positions(count, extra=None):
    """An accessor of `count` positions with no buffer view (all zero) but three made
    distinct by a sparse substitution, so they span a triangle of non-zero area."""
    indices = struct.pack("<3I", 0, 1, 2)
    values = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    buffer = indices + values
    gltf = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(buffer), "uri": data_uri(buffer)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 12},
            {"buffer": 0, "byteOffset": 12, "byteLength": 36},
        ],
        "accessors": [{
            "componentType": 5126, "count": count, "type": "VEC3",
            "min": [0, 0, 0], "max": [1, 1, 0],
            "sparse": {"count": 3, "indices": {"bufferView": 0, "componentType": 5125},
                       "values": {"bufferView": 1}},
        }],
    }
    if extra:
        extra(gltf)
    return gltf


def one_mesh(primitives=1):
    def add(gltf):
        gltf["meshes"] = [{"primitives": [{"attributes": {"POSITION": 0}}] * primitives}]
        gltf["nodes"] = [{"mesh": 0}]
        gltf["scenes"] = [{"nodes": [0]}]
    return add


def instanced(copies):
    def add(gltf):
        gltf["meshes"] = [{"primitives": [{"attributes": {"POSITION": 0}}]}]
        gltf["nodes"] = [{"mesh": 0, "translation": [i * 2.0, 0, 0]} for i in range(copies)]
        gltf["scenes"] = [{"nodes": list(range(copies))}]
    return add


def textured(copies, side):
    """One triangle whose materials use `copies` textures of one `side`² PNG."""
    image = png(side, side)
    w = [10497, 33648, 33071]
    positions = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    uvs = struct.pack("<6f", 0, 0, 1, 0, 0, 1)
    buffer = positions + uvs
    return {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(buffer), "uri": data_uri(buffer)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
        ],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(image).decode()}],
        "samplers": [{"wrapS": w[i % 3], "wrapT": w[i // 3 % 3]} for i in range(min(copies, 9))],
        "textures": [{"source": 0, "sampler": i % 9} for i in range(copies)],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": i}}} for i in range(copies)],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": i}
                                   for i in range(copies)]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
    }


def at_one_point(count):
    """`count` triangles whose vertices all lie at the origin (no buffer view: zeros,
    with one sparse substitution of a zero, as the glTF crate asks of such accessors)."""
    zero = struct.pack("<I3f", 0, 0, 0, 0)
    return {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(zero), "uri": data_uri(zero)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 4},
                        {"buffer": 0, "byteOffset": 4, "byteLength": 12}],
        "accessors": [{"componentType": 5126, "count": count * 3, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 0],
                       "sparse": {"count": 1, "indices": {"bufferView": 0, "componentType": 5125},
                                  "values": {"bufferView": 1}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
    }


def triangle(extra):
    """A valid triangle over a ground, changed by `extra`."""
    positions = struct.pack("<9f", -1, 0, -1, 1, 0, -1, 0, 0, 1)
    gltf = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(positions), "uri": data_uri(positions)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [-1, 0, -1], "max": [1, 0, 1]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1]}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
        "nodes": [{"mesh": 0, "translation": [0, 1, 0]}],
        "scenes": [{"nodes": [0]}],
    }
    extra(gltf)
    return gltf


def main(folder):
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    files = {
        "textures-16-of-one-4096-png.gltf": textured(16, 4096),
        "textures-200-of-one-4096-png.gltf": textured(200, 4096),
        "sparse-60m-vertices.gltf": sparse_positions(60_000_000, one_mesh()),
        "sparse-30m-vertices.gltf": sparse_positions(30_000_000, one_mesh()),
        "primitives-300-sharing-4m-vertices.gltf": sparse_positions(3_999_999, one_mesh(300)),
        "instances-100-of-3m-vertices.gltf": sparse_positions(3_000_000, instanced(100)),
        "mesh-of-2m-vertices.gltf": sparse_positions(2_100_000, one_mesh()),
        "triangles-33k-at-one-point.gltf": at_one_point(33_333),
        "triangles-1m-at-one-point.gltf": at_one_point(1_000_000),
        "camera-without-zfar.gltf": triangle(lambda g: (
            g.update(cameras=[{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 1e-4}}]),
            g["nodes"].append({"camera": 0, "translation": [0, 2, 12]}),
            g["scenes"][0]["nodes"].append(1))),
        "base-color-of-1e30.gltf": triangle(lambda g: g["materials"][0]["pbrMetallicRoughness"].update(
            baseColorFactor=[1e30, -1, 1, 1])),
        "alpha-cutoff-negative.gltf": triangle(lambda g: g["materials"][0].update(alphaMode="MASK", alphaCutoff=-1)),
        "alpha-0-mask.gltf": triangle(lambda g: (g["materials"][0].update(alphaMode="MASK"),
                                                 g["materials"][0]["pbrMetallicRoughness"].update(
                                                     baseColorFactor=[1, 1, 1, 0]))),
    }
    for name, gltf in files.items():
        (out / name).write_text(json.dumps(gltf))
    # The alpha pair: the same name, opaque and then cut away, for the cache's key.
    (out / "alpha-1.gltf").write_text(json.dumps(triangle(lambda g: None)))
    # A scene file of a dozen models of one file, each under the budget alone.
    (out / "twelve-models.toml").write_text(
        "".join(f'[[model]]\nfile = "mesh-of-2m-vertices.gltf"\ntranslation = [{i * 3}, 0, 0]\n\n' for i in range(12)))
    (out / "image-8000-squared.toml").write_text(
        'builtin = "spheres"\n[settings.image]\nwidth = 8000\nheight = 8000\n')
    (out / "pagemap.toml").write_text('[[model]]\nfile = "/proc/self/pagemap"\n')
    (out / "translation-of-4.toml").write_text('[[model]]\nfile = "alpha-1.gltf"\ntranslation = [0, 1, 2, 3]\n')
    for path in sorted(out.iterdir()):
        assert path.stat().st_size < 64 * 1024, f"{path.name} is {path.stat().st_size} bytes"


if __name__ == "__main__":
    main(sys.argv[1])
