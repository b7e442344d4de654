"""The file format of a :class:`bvhkit.TriangleMesh` (``save``/``load``, ``to_bytes``/``from_bytes``
and pickling): the mesh, the builder's name and the files of the trees built so far, so that a
loaded scene rebuilds nothing (but a ray tree with spatial splits, which has no file) and answers
bit for bit as the saved one. Layout: docs/scale-out.md.

The trees are stored as the library's own tree files (docs/serialization.md), which the C++ loaders
check in full; this container adds a header, the mesh arrays and a checksum over everything.
"""

from __future__ import annotations

import hashlib
import struct
from typing import Any, Optional

import numpy as np

MAGIC = b"BVHKSC\x1a\n"
VERSION = 1
_HEADER = struct.Struct("<8sIBBH7Q")  # magic, version, scalar, flags, reserved, 7 counts
HEADER_SIZE = _HEADER.size + 8  # + the checksum
_SCALARS = {1: np.dtype("<f4"), 2: np.dtype("<f8")}
_HAS_SDF, _HAS_WINDING = 1, 2
# A ray tree with spatial splits has no file: its section lists the faces left out of it (u32,
# ascending) and loading builds it again without them, with the fast ray test when _FAST is set.
_SPATIAL_SPLITS, _FAST = 4, 8
_FLAGS = _HAS_SDF | _HAS_WINDING | _SPATIAL_SPLITS | _FAST

load_count: int = 0
"""How many scenes this process has loaded (from_bytes, load, unpickling); a diagnostic, read by
the tests to see how often workers deserialize a scene."""


def _pad(n: int) -> int:
    return -n % 8


def _checksum(header: bytes, payload: Any) -> bytes:
    h = hashlib.blake2b(digest_size=8)
    h.update(header)
    h.update(payload)
    return h.digest()


def _join_sections(sections: list) -> bytes:
    """The sections, each padded with zeros to a multiple of 8 bytes."""
    return b"".join(s + bytes(_pad(len(s))) for s in sections)


def _split_sections(payload: Any, sizes: list, fail: Any) -> list:
    """The sections of `sizes` bytes out of `payload`, checking that they fill it exactly and that
    every padding byte is zero; `fail(message)` makes the exception to raise."""
    # Python integers do not overflow: a forged count just makes this sum too large.
    if sum(s + _pad(s) for s in sizes) != len(payload):
        raise fail("the section sizes do not add up to the payload")
    parts = []
    at = 0
    for s in sizes:
        parts.append(payload[at : at + s])
        if any(payload[at + s : at + s + _pad(s)]):
            raise fail("non-zero padding")
        at += s + _pad(s)
    return parts


def encode(dtype: np.dtype, builder: str, state: tuple) -> bytes:
    """The container's bytes from the scene's ``state()`` (C++: mesh arrays and tree files)."""
    vertices, faces, ray_test, tree, sdf, winding, spatial_splits = state
    scalar = 1 if dtype == np.float32 else 2
    name = builder.encode("utf-8")
    flags = (_HAS_SDF if sdf is not None else 0) | (_HAS_WINDING if winding is not None else 0)
    if spatial_splits:
        flags |= _SPATIAL_SPLITS | (_FAST if ray_test == "fast" else 0)
    sections = [
        name,
        np.ascontiguousarray(vertices, _SCALARS[scalar]).tobytes(),
        np.ascontiguousarray(faces, "<u4").tobytes(),
        tree,
        sdf or b"",
        winding or b"",
    ]
    payload = _join_sections(sections)
    header = _HEADER.pack(
        MAGIC,
        VERSION,
        scalar,
        flags,
        0,
        len(vertices),
        len(faces),
        len(name),
        len(tree),
        len(sdf or b""),
        len(winding or b""),
        len(payload),
    )
    return header + _checksum(header, payload) + payload


class Decoded:
    """The parts of a container, checked against its size and checksum (the trees are checked by
    the C++ loaders)."""

    dtype: np.dtype
    builder: str
    vertices: np.ndarray
    faces: np.ndarray
    tree: bytes
    sdf: Optional[bytes]
    winding: Optional[bytes]
    spatial_splits: bool  # the ray tree is built again (tree lists the faces left out)
    fast: bool  # ... with the fast ray test


def decode(data: Any, what: str) -> Decoded:
    """Splits a container into its parts; ValueError starting with ``what`` if anything is off."""

    def fail(msg: str) -> ValueError:
        return ValueError(f"{what}: {msg}")

    try:
        view = memoryview(data).cast("B")
    except TypeError:
        raise TypeError(
            f"{what}: must be bytes-like, not {type(data).__name__}"
        ) from None
    if len(view) < HEADER_SIZE:
        raise fail(f"{len(view)} bytes, shorter than the {HEADER_SIZE}-byte header")
    magic, version, scalar, flags, reserved, nv, nf, nname, ntree, nsdf, nwinding, npayload = (
        _HEADER.unpack_from(view)
    )
    if magic != MAGIC:
        raise fail("not a bvhkit TriangleMesh file (wrong magic)")
    if version != VERSION:
        raise fail(f"format version {version}, this bvhkit reads {VERSION}")
    if scalar not in _SCALARS:
        raise fail(f"unknown scalar code {scalar}")
    if flags & ~_FLAGS or reserved:
        raise fail("reserved bits set")
    if flags & _FAST and not flags & _SPATIAL_SPLITS:
        raise fail("the fast-test flag without the spatial-splits flag")
    if npayload != len(view) - HEADER_SIZE:
        raise fail(f"the header says {npayload} payload bytes, there are {len(view) - HEADER_SIZE}")
    payload = view[HEADER_SIZE:]
    if _checksum(bytes(view[: _HEADER.size]), payload) != bytes(view[_HEADER.size : HEADER_SIZE]):
        raise fail("checksum mismatch (the data is damaged)")
    if bool(flags & _HAS_SDF) != (nsdf > 0) or bool(flags & _HAS_WINDING) != (nwinding > 0):
        raise fail("flags and section sizes disagree")
    dtype = _SCALARS[scalar]
    sizes = [nname, 3 * nv * dtype.itemsize, 3 * nf * 4, ntree, nsdf, nwinding]
    parts = _split_sections(payload, sizes, fail)
    d = Decoded()
    d.dtype = np.dtype(np.float32 if scalar == 1 else np.float64)
    try:
        d.builder = bytes(parts[0]).decode("utf-8")
    except UnicodeDecodeError:
        raise fail("the builder's name is not UTF-8") from None
    d.vertices = np.frombuffer(parts[1], dtype).astype(d.dtype).reshape(nv, 3)
    d.faces = np.frombuffer(parts[2], "<u4").astype(np.int64).reshape(nf, 3)
    d.tree = bytes(parts[3])
    d.sdf = bytes(parts[4]) if nsdf else None
    d.winding = bytes(parts[5]) if nwinding else None
    d.spatial_splits = bool(flags & _SPATIAL_SPLITS)
    d.fast = bool(flags & _FAST)
    return d
