// LBVH construction after Karras 2012, "Maximizing Parallelism in the Construction of BVHs,
// Octrees, and k-d Trees". OpenCL C 1.2, no extensions: PoCL runs it on the CPU here, and any
// OpenCL 1.2 GPU runs it unchanged. The host (native/accel/lbvh_builder.cpp) runs the stages in
// this order, one kernel each:
//   centroid_bounds -> morton_codes -> (radix_histogram, radix_scan, radix_scatter) per digit
//   -> emit_hierarchy -> gather_bounds -> propagate_bounds -> write_bvh_nodes
// Shared layouts are described byte by byte in native/accel/lbvh_layout.h, which static_asserts
// them on the host side.

// The host computes the same Morton codes for its reference builder: no contraction of a * b + c
// into a fused multiply-add, so both sides round identically.
#pragma OPENCL FP_CONTRACT OFF

// 32 bytes, as LbvhNode in lbvh_layout.h. A child >= 0 is an internal node, a child < 0 is the
// leaf ~child (the sorted primitive slot). Bounds are written by propagate_bounds.
typedef struct {
  float lo[3];  // bytes 0-11
  int left;     // bytes 12-15
  float hi[3];  // bytes 16-27
  int right;    // bytes 28-31
} LbvhNode;

// 32 bytes, as Node in native/accel/node.h: the flat BVH every builder produces.
typedef struct {
  float bounds[6];  // bytes 0-23: lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
  uint first;       // bytes 24-27: interior: index of the left child (right = first + 1); leaf: first slot
  uint count;       // bytes 28-31: 0 for an interior node, else the leaf's primitive count
} BvhNode;

// Stage 1: centroid bounds. Work-item g reduces centres g, g + G, g + 2G, ... into six floats
// partial[6g .. 6g + 5] = (lo.x, lo.y, lo.z, hi.x, hi.y, hi.z); the host reduces the G partials.
__kernel void centroid_bounds(__global const float* centers, uint n, __global float* partial) {
  const uint g = get_global_id(0), stride = get_global_size(0);
  float lx = INFINITY, ly = INFINITY, lz = INFINITY, hx = -INFINITY, hy = -INFINITY, hz = -INFINITY;
  for (uint i = g; i < n; i += stride) {
    const float x = centers[3 * i], y = centers[3 * i + 1], z = centers[3 * i + 2];
    lx = fmin(lx, x); ly = fmin(ly, y); lz = fmin(lz, z);
    hx = fmax(hx, x); hy = fmax(hy, y); hz = fmax(hz, z);
  }
  partial[6 * g] = lx; partial[6 * g + 1] = ly; partial[6 * g + 2] = lz;
  partial[6 * g + 3] = hx; partial[6 * g + 4] = hy; partial[6 * g + 5] = hz;
}

// Spreads the low `bits` bits of v so that two zero bits separate each (bit k moves to 3k).
ulong spread_bits(ulong v, uint bits) {
  ulong out = 0;
  for (uint k = 0; k < bits; ++k) out |= ((v >> k) & 1UL) << (3 * k);
  return out;
}

// Stage 2: Morton codes of the centres, quantised to 2^bits_per_axis cells per axis of the
// centroid box. `scale` is cells / extent per axis, computed once by the host (0 for a flat axis).
__kernel void morton_codes(__global const float* centers, uint n, float lo_x, float lo_y, float lo_z,
                           float scale_x, float scale_y, float scale_z, uint bits_per_axis,
                           __global ulong* keys, __global uint* values) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const float cells = (float)((1u << bits_per_axis) - 1u);
  const float qx = fmin(fmax((centers[3 * i] - lo_x) * scale_x, 0.0f), cells);
  const float qy = fmin(fmax((centers[3 * i + 1] - lo_y) * scale_y, 0.0f), cells);
  const float qz = fmin(fmax((centers[3 * i + 2] - lo_z) * scale_z, 0.0f), cells);
  keys[i] = (spread_bits((ulong)qx, bits_per_axis) << 2) | (spread_bits((ulong)qy, bits_per_axis) << 1) |
            spread_bits((ulong)qz, bits_per_axis);
  values[i] = i;
}

// Stage 3: a stable least-significant-digit radix sort of (key, value) pairs, 8 bits per pass.
// The input is cut into blocks of `block` pairs, one work-item each, walked in order, which is
// what keeps equal keys in index order (the tie-break emit_hierarchy relies on).
// hist is digit-major: hist[digit * blocks + b] counts `digit` in block b, so one exclusive scan
// of it gives every (digit, block) its first output slot.
__kernel void radix_histogram(__global const ulong* keys, uint n, uint shift, uint block, __global uint* hist) {
  const uint b = get_global_id(0), blocks = get_global_size(0);
  uint count[256];
  for (uint d = 0; d < 256; ++d) count[d] = 0;
  const uint end = min(n, (b + 1) * block);
  for (uint i = b * block; i < end; ++i) ++count[(keys[i] >> shift) & 255UL];
  for (uint d = 0; d < 256; ++d) hist[d * blocks + b] = count[d];
}

// Exclusive prefix sum of hist[0 .. count) in place, by one work-item (count is 256 x blocks,
// small next to n).
__kernel void radix_scan(__global uint* hist, uint count) {
  if (get_global_id(0) != 0) return;
  uint sum = 0;
  for (uint i = 0; i < count; ++i) {
    const uint c = hist[i];
    hist[i] = sum;
    sum += c;
  }
}

__kernel void radix_scatter(__global const ulong* keys_in, __global const uint* values_in, uint n, uint shift,
                            uint block, __global const uint* offsets, __global ulong* keys_out,
                            __global uint* values_out) {
  const uint b = get_global_id(0), blocks = get_global_size(0);
  uint next[256];
  for (uint d = 0; d < 256; ++d) next[d] = offsets[d * blocks + b];
  const uint end = min(n, (b + 1) * block);
  for (uint i = b * block; i < end; ++i) {
    const ulong k = keys_in[i];
    const uint slot = next[(k >> shift) & 255UL]++;
    keys_out[slot] = k;
    values_out[slot] = values_in[i];
  }
}

// Length of the common prefix of sorted keys i and j; -1 outside [0, n). Equal keys (duplicate
// Morton codes) are told apart by their indices, as if each key were followed by its index:
// Karras' tie-break, which keeps the hierarchy a valid binary tree when centroids coincide.
int common_prefix(__global const ulong* keys, long n, long i, long j) {
  if (j < 0 || j >= n) return -1;
  const ulong a = keys[i], b = keys[j];
  if (a == b) return 64 + (int)clz((uint)(i ^ j));
  return (int)clz(a ^ b);
}

// Stage 4: one work-item per internal node i in [0, n - 2] finds the range of sorted leaves it
// covers and where that range splits (Karras 2012, section 4). Internal node 0 is the root.
__kernel void emit_hierarchy(__global const ulong* keys, uint n_leaves, __global LbvhNode* nodes,
                             __global int* internal_parent, __global int* leaf_parent, __global uint2* range) {
  const long i = get_global_id(0), n = n_leaves;
  if (i >= n - 1) return;
  // Direction of the range: towards the neighbour sharing the longer prefix.
  const int d = common_prefix(keys, n, i, i + 1) - common_prefix(keys, n, i, i - 1) >= 0 ? 1 : -1;
  // Upper bound of the range's length, then its exact other end j by binary search.
  const int min_prefix = common_prefix(keys, n, i, i - d);
  long max_len = 2;
  while (common_prefix(keys, n, i, i + max_len * d) > min_prefix) max_len *= 2;
  long len = 0;
  for (long t = max_len / 2; t >= 1; t /= 2)
    if (common_prefix(keys, n, i, i + (len + t) * d) > min_prefix) len += t;
  const long j = i + len * d;
  // The split: the last position sharing more than the whole range's prefix with i.
  const int node_prefix = common_prefix(keys, n, i, j);
  long split = 0;
  for (long div = 2;; div *= 2) {
    const long t = (len + div - 1) / div;
    if (common_prefix(keys, n, i, i + (split + t) * d) > node_prefix) split += t;
    if (t == 1) break;
  }
  const long gamma = i + split * d + min(d, 0);
  const long first = min(i, j), last = max(i, j);
  const int left = first == gamma ? ~(int)gamma : (int)gamma;
  const int right = last == gamma + 1 ? ~(int)(gamma + 1) : (int)(gamma + 1);
  nodes[i].left = left;
  nodes[i].right = right;
  range[i] = (uint2)((uint)first, (uint)last);  // the leaves it covers, for write_bvh_nodes
  if (left < 0) leaf_parent[~left] = (int)i; else internal_parent[left] = (int)i;
  if (right < 0) leaf_parent[~right] = (int)i; else internal_parent[right] = (int)i;
  if (i == 0) internal_parent[0] = -1;
}

// Stage 5a: the primitives' boxes in sorted order, so that the climb below reads its leaves'
// boxes from neighbouring memory rather than chasing values[] across the whole array.
__kernel void gather_bounds(__global const float* prim_bounds, __global const uint* values, uint n,
                            __global float* sorted_bounds) {
  const uint k = get_global_id(0);
  if (k >= n) return;
  __global const float* b = prim_bounds + 6 * values[k];
  for (int a = 0; a < 6; ++a) sorted_bounds[6 * k + a] = b[a];
}

void child_bounds(__global const float* sorted_bounds, volatile __global LbvhNode* nodes, int child, float* lo,
                  float* hi) {
  if (child < 0) {
    __global const float* b = sorted_bounds + 6 * ~child;
    for (int a = 0; a < 3; ++a) { lo[a] = b[a]; hi[a] = b[3 + a]; }
  } else {
    for (int a = 0; a < 3; ++a) { lo[a] = nodes[child].lo[a]; hi[a] = nodes[child].hi[a]; }
  }
}

// Stage 5: bounds, bottom up. Every leaf's work-item climbs towards the root; at each internal
// node the first arrival stops (atomic flag) and the second, whose sibling subtree is then
// complete, writes the node's box and climbs on. sorted_bounds holds six floats per leaf
// (lo.xyz, hi.xyz) in sorted order (gather_bounds).
__kernel void propagate_bounds(__global const float* sorted_bounds, uint n_leaves,
                               volatile __global LbvhNode* nodes, __global const int* internal_parent,
                               __global const int* leaf_parent, volatile __global int* flags) {
  const uint k = get_global_id(0);
  if (k >= n_leaves) return;
  int node = leaf_parent[k];
  while (node >= 0) {
    mem_fence(CLK_GLOBAL_MEM_FENCE);  // our child's box is visible before we announce arrival
    if (atomic_inc(&flags[node]) == 0) return;
    mem_fence(CLK_GLOBAL_MEM_FENCE);
    float llo[3], lhi[3], rlo[3], rhi[3];
    child_bounds(sorted_bounds, nodes, nodes[node].left, llo, lhi);
    child_bounds(sorted_bounds, nodes, nodes[node].right, rlo, rhi);
    for (int a = 0; a < 3; ++a) {
      nodes[node].lo[a] = fmin(llo[a], rlo[a]);
      nodes[node].hi[a] = fmax(lhi[a], rhi[a]);
    }
    node = internal_parent[node];
  }
}

// Where the flat BVH keeps the children of internal node p: each split position gamma (between
// sorted leaves gamma and gamma + 1) belongs to exactly one internal node, so the pair
// (1 + 2 gamma, 2 + 2 gamma) is a unique, adjacent home for its two children; the root is 0.
uint child_slot(__global const LbvhNode* nodes, int p, int child) {
  const int left = nodes[p].left;
  const int gamma = left >= 0 ? left : ~left;
  return 1u + 2u * (uint)gamma + (nodes[p].right == child ? 1u : 0u);
}

// Stage 6: the flat BVH (native/accel/node.h layout), written in place on the device so that
// neither the Karras nodes nor a host-side conversion are needed. Work-items 0 .. n - 2 write the
// internal nodes, n - 1 .. 2n - 2 the leaves (one primitive each, slot k of the sorted order).
// Beside each node, the sorted slots under it (first, count): the host's collapse to the wide
// layout needs them, and deriving them there took a walk of the whole tree.
__kernel void write_bvh_nodes(__global const LbvhNode* nodes, __global const int* internal_parent,
                              __global const int* leaf_parent, __global const float* sorted_bounds, uint n_leaves,
                              __global BvhNode* out, __global const uint2* range, __global uint2* out_range) {
  const uint id = get_global_id(0);
  const uint internal = n_leaves - 1;
  if (id >= internal + n_leaves) return;
  BvhNode node;
  uint at;
  if (id < internal) {
    const int i = (int)id;
    at = i == 0 ? 0u : child_slot(nodes, internal_parent[i], i);
    for (int a = 0; a < 3; ++a) {
      node.bounds[a] = nodes[i].lo[a];
      node.bounds[3 + a] = nodes[i].hi[a];
    }
    const int left = nodes[i].left;
    node.first = 1u + 2u * (uint)(left >= 0 ? left : ~left);
    node.count = 0u;
    out_range[at] = (uint2)(range[i].x, range[i].y - range[i].x + 1u);
  } else {
    const int k = (int)(id - internal);
    at = child_slot(nodes, leaf_parent[k], ~k);
    for (int a = 0; a < 6; ++a) node.bounds[a] = sorted_bounds[6 * k + a];
    node.first = (uint)k;
    node.count = 1u;
    out_range[at] = (uint2)((uint)k, 1u);
  }
  out[at] = node;
}
