"""The dynamic trees against brute-force box tests."""

import numpy as np
import pytest

import bvhkit


def overlaps(lo1, hi1, lo2, hi2):
    return np.all((lo1[:, None] <= hi2[None]) & (lo2[None] <= hi1[:, None]), axis=-1)


def brute_pairs(lo, hi, ids):
    o = overlaps(lo, hi, lo, hi)
    i, j = np.nonzero(np.triu(o, 1))
    p = np.stack([ids[i], ids[j]], 1)
    p.sort(axis=1)
    return {tuple(x) for x in p}


@pytest.mark.parametrize("cls,dim", [(bvhkit.DynamicTree2D, 2), (bvhkit.DynamicTree3D, 3)])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_pairs_queries_and_rays(cls, dim, dtype):
    rng = np.random.default_rng(dim)
    n = 400
    lo = rng.uniform(0, 20, (n, dim)).astype(dtype)
    hi = lo + rng.uniform(0.1, 1.5, (n, dim)).astype(dtype)
    tree = cls(dtype=dtype)
    ids = tree.create(lo, hi)
    assert len(set(ids.tolist())) == n and len(tree) == n
    tree.validate()
    pairs = tree.find_pairs()
    assert {tuple(x) for x in pairs} == brute_pairs(lo, hi, ids)
    assert len(tree.find_pairs()) == 0  # nothing moved since
    # Move a third of them; the new pairs are those that involve a moved proxy.
    moved = rng.choice(n, n // 3, replace=False)
    shift = rng.uniform(-2, 2, (len(moved), dim)).astype(dtype)
    lo[moved] += shift
    hi[moved] += shift
    tree.move(ids[moved], lo[moved], hi[moved], displacement=shift)
    tree.validate()
    got = {tuple(x) for x in tree.find_pairs()}
    mset = set(ids[moved].tolist())
    want = {p for p in brute_pairs(lo, hi, ids) if p[0] in mset or p[1] in mset}
    assert got == want
    # Box queries.
    qlo = rng.uniform(0, 20, (50, dim)).astype(dtype)
    qhi = qlo + 2
    rows = tree.query(qlo, qhi)
    o = overlaps(qlo, qhi, lo, hi)
    assert {tuple(x) for x in rows} == {(q, ids[k]) for q, k in zip(*np.nonzero(o))}
    # Ray casts against a numpy slab test.
    org = rng.uniform(-1, 21, (50, dim)).astype(dtype)
    dirn = rng.uniform(-10, 10, (50, dim)).astype(dtype)
    rows = tree.ray_cast(org, dirn)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / dirn.astype(np.float64)
        t1 = (lo[None] - org[:, None]) * inv[:, None]
        t2 = (hi[None] - org[:, None]) * inv[:, None]
    tn = np.nanmax(np.minimum(t1, t2), axis=-1)
    tf = np.nanmin(np.maximum(t1, t2), axis=-1)
    hit = (tn <= tf) & (tf >= 0) & (tn <= 1)
    clear = (np.abs(tn - tf) > 1e-3) & (np.abs(tf) > 1e-3) & (np.abs(tn - 1) > 1e-3)
    got = np.zeros_like(hit)
    slot = {int(i): k for k, i in enumerate(ids)}
    for r, i in rows:
        got[r, slot[int(i)]] = True
    np.testing.assert_array_equal(got[clear], hit[clear])
    # Destroy some; boxes() gives back the tight boxes.
    tree.destroy(ids[:10])
    assert len(tree) == n - 10
    blo, bhi = tree.boxes(ids[10:20])
    np.testing.assert_array_equal(blo, lo[10:20])
    np.testing.assert_array_equal(bhi, hi[10:20])
    tree.rebuild()
    tree.validate()


def test_bad_batches_change_nothing():
    tree = bvhkit.DynamicTree3D()
    ids = tree.create([[0, 0, 0], [1, 1, 1]], [[1, 1, 1], [2, 2, 2]])
    with pytest.raises(ValueError, match="lo"):
        tree.create([[0, 0, 0], [1, 1, 1]], [[1, 1, 1], [0, 2, 2]])  # min > max in row 1
    with pytest.raises(ValueError, match="ids"):
        tree.move([ids[0], 99], [[0, 0, 0]] * 2, [[1, 1, 1]] * 2)
    with pytest.raises(ValueError, match="ids"):
        tree.destroy([ids[0], ids[0]])
    with pytest.raises(ValueError, match="hi"):
        tree.create([[0, 0, 0]], [[np.nan, 1, 1]])
    assert len(tree) == 2
    tree.validate()


def test_destroy_checks_repeats_in_linear_time():
    # Issue 38: destroy() compared every pair of ids (80,000 took 12.9 s under the tree's lock).
    # 200,000 take a fraction of a second now; a repeat anywhere is still refused, naming both
    # positions, and nothing is destroyed.
    import time

    n = 200_000
    tree = bvhkit.DynamicTree2D()
    lo = np.stack([np.arange(n) % 500, np.arange(n) // 500], 1).astype(np.float32) * 3
    start = time.perf_counter()
    ids = tree.create(lo, lo + 1)
    create_s = time.perf_counter() - start
    batch = ids[::-1].copy()
    batch[n - 1] = batch[7]  # the last repeats the eighth
    with pytest.raises(ValueError, match=rf"ids\[{n - 1}\] repeats ids\[7\]"):
        tree.destroy(batch)
    assert len(tree) == n
    tree.validate()
    start = time.perf_counter()
    tree.destroy(ids[::-1])
    destroy_s = time.perf_counter() - start
    assert len(tree) == 0
    tree.validate()
    # Destroying costs about what creating did (one detach per proxy, plus the sort). The pairwise
    # check alone took 45 s here (2e10 comparisons), hundreds of times the create: the bound holds
    # a twentyfold margin, measured against this machine's own speed.
    assert destroy_s < max(2.0, 20 * create_s), (destroy_s, create_s)


def test_stale_ids_are_refused_and_never_name_a_new_proxy():
    # Issue 38: ids were slots alone, so an id kept past destroy() named the proxy created next in
    # its slot. Ids carry a generation: the kept id is refused, naming it, and a new proxy in the
    # same slot gets a different id.
    tree = bvhkit.DynamicTree2D()
    ids = tree.create([[0, 0], [0.5, 0]], [[1, 1], [1.5, 1]])
    assert {tuple(p) for p in tree.find_pairs()} == {tuple(sorted(ids.tolist()))}
    old = int(ids[1])
    tree.destroy([old])
    (new,) = tree.create([[0.5, 0]], [[1.5, 1]])
    assert int(new) != old and (int(new) & 0xFFFFFFFF) == (old & 0xFFFFFFFF)  # same slot
    for call in (
        lambda: tree.move([old], [[0, 0]], [[1, 1]]),
        lambda: tree.boxes([old]),
        lambda: tree.destroy([old]),
    ):
        with pytest.raises(ValueError, match=rf"ids\[0\] = {old} is not a live proxy"):
            call()
    assert len(tree) == 2
    pairs = tree.find_pairs()
    assert pairs.dtype == np.int64
    assert {tuple(p) for p in pairs} == {tuple(sorted([int(ids[0]), int(new)]))}
    rows = tree.query([[0, 0]], [[2, 2]])
    assert sorted(rows[:, 1].tolist()) == sorted([int(ids[0]), int(new)])
    tree.validate()
