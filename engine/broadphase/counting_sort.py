"""The two-pass (MSD radix) counting sort by cell number shared by the uniform grids (Ericson 7.1.6).

Entries (boxes entering cells, or sphere centres) are sorted by their cell number so that each cell's entries
end up contiguous. One counting sort over millions of cells would thrash the cache with its counters, so the
sort runs in two passes whose counters both stay in cache: first on the high bits of the cell number (at most
2048 buckets, ``radix_split``), the payload moved bucket by bucket by the caller, then each bucket on its low
bits (``sort_within_buckets``), which gives every entry its final slot. ``cell_of`` gives the cell column of a
coordinate and ``grid_dims`` the cells per axis under a cap on their number, the same way for every grid.
The first pass can be shared among threads: each counts the buckets of its chunk of the input, ``bucket_offsets``
gives each chunk its slots in every bucket (after the lower buckets and the earlier chunks' entries), and each
chunk moves its own entries (``sphere_cells.scatter_spheres``) — the order is that of the one-thread pass, for
any split.
"""
from __future__ import annotations

import numpy as np

from engine._config import njit

#: most buckets of the first pass (their counters fit in cache)
MAX_BUCKETS = 2048


@njit
def cell_of(v, origin, inv_size, k):
    """Grid column of coordinate v: floor((v − origin) / size) clamped to [0, k) — monotone in v. A NaN
    (0 · inf when a span below the denormal range gives an infinite 1 / size) counts as column 0, like any value
    below the origin: only finite values in [0, k) reach the float → int conversion (it is undefined outside)."""
    t = (v - origin) * inv_size
    if not t >= 0.0:
        return 0
    if t >= k:
        return k - 1
    return int(t)


@njit
def grid_dims(origin, top, cell_size, max_cells, max_per_axis):
    """(side, nx, ny, nz): cells of side ``cell_size`` over the box [origin, top] ((3,) float64 each), the side
    doubled until the grid has at most ``max_cells`` cells (a cap on memory: far-apart clusters then share
    coarse cells) and at most ``max_per_axis`` cells along each axis. The counts are compared as floats before
    any conversion to int: a tiny side (a denormal one, from boxes near 1e-323) over a span of 1 gives counts
    past 2^63, which no int64 holds."""
    size = cell_size
    while True:
        total = 1.0
        widest = 1.0
        for k in range(3):
            cells = np.floor((top[k] - origin[k]) / size) + 1.0
            total *= cells
            widest = max(widest, cells)
        if total <= max_cells and widest <= max_per_axis:
            break
        size *= 2.0
    nx = int(np.floor((top[0] - origin[0]) / size)) + 1
    ny = int(np.floor((top[1] - origin[1]) / size)) + 1
    nz = int(np.floor((top[2] - origin[2]) / size)) + 1
    return size, nx, ny, nz


@njit
def radix_split(n_cells):
    """(shift, n_buckets): the bucket of cell number c is c >> shift, with at most MAX_BUCKETS buckets."""
    shift = 0
    while ((n_cells - 1) >> shift) >= MAX_BUCKETS:
        shift += 1
    return shift, ((n_cells - 1) >> shift) + 1


@njit
def sort_within_buckets(keys, bucket_start, shift, n_cells, start):
    """Second pass: the final slot of each entry, and the first slot of each cell.

    keys ((e,) int64): the cell numbers of the entries, already grouped by bucket (bucket b holds the entries
    bucket_start[b] .. bucket_start[b + 1] − 1, bucket_start (n_buckets + 1,) int64); writes start[c] (start
    int64, at least (n_cells,)) for every cell c < n_cells; returns dest (e,) int64 with dest[t] the sorted
    position of entry t (stable within a cell).
    """
    dest = np.empty(keys.shape[0], dtype=np.int64)
    width = 1 << shift
    local = np.zeros(width + 1, dtype=np.int64)
    for b in range(bucket_start.shape[0] - 1):
        first_cell = b << shift
        m = min(n_cells, first_cell + width) - first_cell
        local[: m + 1] = 0
        for t in range(bucket_start[b], bucket_start[b + 1]):
            local[keys[t] - first_cell + 1] += 1
        local[0] = bucket_start[b]
        for u in range(m):
            local[u + 1] += local[u]
            start[first_cell + u] = local[u]
        for t in range(bucket_start[b], bucket_start[b + 1]):
            u = keys[t] - first_cell
            dest[t] = local[u]
            local[u] += 1
    return dest


@njit
def radix_sort_pairs(keys, values, keys_tmp, values_tmp, n):
    """Stable LSD radix sort of keys[:n] (non-negative integers), carrying values[:n] along (values and
    values_tmp may both be empty: keys only).

    Digits of at most 11 bits (2048 counters, in cache), as few as the largest key needs; the histograms of all
    the digits are counted in one read pass, and a digit on which every key agrees is skipped. keys_tmp and
    values_tmp are scratch arrays of the same dtypes and at least n entries. Returns (sorted keys, values): each
    is one of the two buffers given, holding the sorted first n entries.
    """
    top = 0
    for t in range(n):
        top = max(top, keys[t])
    bits = 0
    while (top >> bits) > 0:
        bits += 1
    passes = (bits + 10) // 11
    if passes == 0:
        return keys, values
    width = (bits + passes - 1) // passes
    mask = (1 << width) - 1
    hist = np.zeros((passes, mask + 1), dtype=np.int64)
    for t in range(n):
        k = keys[t]
        for d in range(passes):
            hist[d, (k >> (d * width)) & mask] += 1
    src_k, src_v, dst_k, dst_v = keys, values, keys_tmp, values_tmp
    for d in range(passes):
        shift = d * width
        if hist[d, (src_k[0] >> shift) & mask] == n:
            continue  # every key has this digit: the order does not change
        total = 0
        for b in range(mask + 1):
            count = hist[d, b]
            hist[d, b] = total
            total += count
        carry = src_v.shape[0] > 0
        for t in range(n):
            b = (src_k[t] >> shift) & mask
            p = hist[d, b]
            hist[d, b] = p + 1
            dst_k[p] = src_k[t]
            if carry:
                dst_v[p] = src_v[t]
        src_k, src_v, dst_k, dst_v = dst_k, dst_v, src_k, src_v
    return src_k, src_v


@njit
def radix_sort_packed(a, tmp, n, low_bit, bits, max_digit_bits):
    """Stable LSD radix sort of a[:n] (non-negative int64) by the key a[t] >> low_bit, of at most ``bits`` bits:
    the key and its payload (the low bits, e.g. an index) move as one 8-byte word, one store stream per bucket.

    Digits of at most ``max_digit_bits`` bits, as few passes as ``bits`` needs, the histograms of all the
    digits counted in one read pass. Fewer buckets are faster once the arrays outgrow the L2 cache: each pass
    then keeps one cache line open per bucket, and 256 of them (8-bit digits) fit in L1 while 2048 do not.
    tmp: scratch int64, at least n entries. Returns the buffer (a or tmp) holding the sorted first n entries.
    """
    if n == 0 or bits == 0:
        return a
    passes = (bits + max_digit_bits - 1) // max_digit_bits
    width = (bits + passes - 1) // passes
    mask = (1 << width) - 1
    hist = np.zeros((passes, mask + 1), dtype=np.int64)
    for t in range(n):
        k = a[t] >> low_bit
        for d in range(passes):
            hist[d, (k >> (d * width)) & mask] += 1
    src, dst = a, tmp
    for d in range(passes):
        total = 0
        for b in range(mask + 1):
            count = hist[d, b]
            hist[d, b] = total
            total += count
        shift = low_bit + d * width
        for t in range(n):
            x = src[t]
            b = (x >> shift) & mask
            p = hist[d, b]
            hist[d, b] = p + 1
            dst[p] = x
        src, dst = dst, src
    return src


@njit
def bucket_offsets(hist):
    """The slots of a parallel counting sort by bucket (Ericson 7.1.6's counting sort, one histogram per
    thread): hist (T, B) int64 counts the entries of bucket b in chunk t of the input; returns (offsets (T, B),
    bucket_start (B + 1,)) with offsets[t, b] the first slot of chunk t's entries of bucket b — after every
    entry of a lower bucket and after the entries of bucket b of the chunks before t, so that the scatter
    (e.g. ``sphere_cells.scatter_spheres``) is stable whatever the number of chunks."""
    chunks, buckets = hist.shape
    offsets = np.empty((chunks, buckets), dtype=np.int64)
    bucket_start = np.empty(buckets + 1, dtype=np.int64)
    total = 0
    for b in range(buckets):
        bucket_start[b] = total
        for t in range(chunks):
            offsets[t, b] = total
            total += hist[t, b]
    bucket_start[buckets] = total
    return offsets, bucket_start

