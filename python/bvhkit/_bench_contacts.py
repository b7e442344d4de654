"""P9 of python -m bvhkit.bench: contacts between a mesh and itself at C1's kind of poses (issue 41's
K2) beside python-fcl's `collide` with contacts, and what FCL's mesh contacts are next to bvhkit's."""

import statistics
import time
from typing import List

import numpy as np

import bvhkit


def _median_per_pose(runs, reps, poses):
    """Interleaved repetitions (one untimed round first); microseconds per pose, and each answer."""
    times = {name: [] for name in runs}
    last = {}
    for rep in range(reps + 1):
        for name, run in runs.items():
            t = time.perf_counter()
            last[name] = run()
            if rep:
                times[name].append(time.perf_counter() - t)
    return {n: statistics.median(t) / poses * 1e6 for n, t in times.items()}, last


def _fcl_against_segments(fcl_contacts, curve, v, f, rot, trans, diag):
    """Where FCL's contact of each triangle pair lies against bvhkit's intersection segment of the
    same pair, and how its normal compares with the segment's curve normal."""
    off_segment, off_plane_b, same_line, flipped = [], [], 0, 0
    for i, contacts in enumerate(fcl_contacts):
        segments = {}
        for pair, p, n in zip(curve[i].faces.tolist(), curve[i].points, curve[i].normals):
            segments.setdefault(tuple(pair), []).append((p, n))
        for c in contacts:
            s = segments.get((c.b1, c.b2))
            if not s:
                continue
            p0, p1, n = s[0][0], s[-1][0], s[0][1]
            d = p1 - p0
            length2 = d @ d
            t = 0.0 if length2 == 0 else float(np.clip((c.pos - p0) @ d / length2, 0, 1))
            off_segment.append(np.linalg.norm(c.pos - (p0 + t * d)) / diag)
            cosine = float(c.normal @ n)
            same_line += abs(abs(cosine) - 1) < 1e-6
            flipped += cosine < 0
            b = v[f[c.b2]] @ rot[i].T + trans[i]
            nb = np.cross(b[1] - b[0], b[2] - b[0])
            off_plane_b.append(abs((c.pos - b[0]) @ nb) / np.linalg.norm(nb) / diag)
    return np.array(off_segment), np.array(off_plane_b), same_line, flipped


def p9(v, f, name, k, reps, fcl) -> List[str]:
    from .bench import _rotations

    v = v.astype(np.float64)
    rng = np.random.default_rng(2026)
    diag = float(np.linalg.norm(v.max(0) - v.min(0)))
    rot = _rotations(rng, k)
    trans = rng.uniform(-0.5, 0.5, (k, 3)) * diag
    model = bvhkit.CollisionModel(v, f, volume="obb", dtype=np.float64)
    hit = bvhkit.collide(model, model, rot, trans)
    rot, trans = rot[hit], trans[hit]
    k = len(rot)
    if k == 0:
        return [f"P9        {name}: no colliding pose"]
    runs = {
        "bvhkit pairs (collide contacts=True)":
            lambda: bvhkit.collide(model, model, rot, trans, contacts=True, threads=1),
        "bvhkit manifold, 4 a region":
            lambda: bvhkit.contacts(model, model, rot, trans, threads=1),
        "bvhkit manifold, walk_inside=False":
            lambda: bvhkit.contacts(model, model, rot, trans, walk_inside=False, threads=1),
        "bvhkit curve contacts only":
            lambda: bvhkit.contacts(model, model, rot, trans, inside_vertices=False, threads=1),
        "bvhkit every curve contact (for the check)":
            lambda: bvhkit.contacts(model, model, rot, trans, max_points=0,
                                    inside_vertices=False, threads=1),
    }
    if fcl is not None:
        fmodel = fcl.BVHModel()
        fmodel.beginModel(len(v), len(f))
        fmodel.addSubModel(v, f.astype(np.int32))
        fmodel.endModel()
        a = fcl.CollisionObject(fmodel, fcl.Transform())

        def fcl_contacts():
            out = []
            for i in range(k):
                b = fcl.CollisionObject(fmodel, fcl.Transform(rot[i], trans[i]))
                result = fcl.CollisionResult()
                fcl.collide(a, b, fcl.CollisionRequest(num_max_contacts=1 << 20,
                                                       enable_contact=True), result)
                out.append(result.contacts)
            return out
        runs["python-fcl collide, contacts"] = fcl_contacts
    per_pose, last = _median_per_pose(runs, reps, k)
    base = per_pose["bvhkit pairs (collide contacts=True)"]
    rows = [f"P9        {name}: {k} colliding poses, "
            f"{sum(len(x) for x in last['bvhkit pairs (collide contacts=True)']) / k:.0f} "
            "intersecting triangle pairs a pose"]
    for label, us in per_pose.items():
        rows.append(f"P9        {label:44} {us:10.1f} us a pose {us / base:8.2f}x the pairs")
    if fcl is not None:
        fc = last["python-fcl collide, contacts"]
        ours = last["bvhkit pairs (collide contacts=True)"]
        theirs = [{(c.b1, c.b2) for c in fc[i]} for i in range(k)]
        mine = [{tuple(p) for p in ours[i].tolist()} for i in range(k)]
        found = sum(len(theirs[i] & mine[i]) for i in range(k))
        only_mine = sum(len(mine[i] - theirs[i]) for i in range(k))
        repeated = sum(len(x) for x in fc) - sum(len(x) for x in theirs)
        off, plane_b, same_line, flipped = _fcl_against_segments(
            fc, last["bvhkit every curve contact (for the check)"], v, f, rot, trans, diag)
        rows.append(f"P9        python-fcl's {sum(len(x) for x in theirs)} triangle pairs "
                    f"({repeated} more contacts repeat a pair): {found} among bvhkit's, "
                    f"{only_mine} of bvhkit's not among FCL's; "
                    f"its point {np.median(off):.1e} (median), {off.max():.1e} (max) of the "
                    f"diagonal from bvhkit's intersection segment, {np.median(plane_b):.0e} from "
                    f"b's face plane; its normal on the same line as bvhkit's curve normal at "
                    f"{same_line}/{len(off)} (opposite sign convention at {flipped})")
    return rows
