// LBVH construction: the binary radix tree of Karras 2012 ("Maximizing Parallelism in the
// Construction of BVHs, Octrees, and k-d Trees"), built bottom up with its boxes in one pass as
// Apetrei 2014 does it ("Fast and Simple Agglomerative LBVH Construction"). OpenCL C 1.2, no extensions: PoCL runs it
// on the CPU here, and any OpenCL 1.2 GPU runs it unchanged. The host (native/accel/lbvh_builder.cpp) runs the stages
// in this order, one kernel each:
//   centroid_bounds -> morton_codes -> (radix_histogram, radix_scan, radix_scatter) per digit
//   -> build_hierarchy (-> write_bvh_nodes, when the flat binary tree is asked for)
// Shared layouts are described byte by byte in native/accel/lbvh_layout.h, which static_asserts
// them on the host side.

// The host computes the same Morton codes for its reference builder: no contraction of a * b + c
// into a fused multiply-add, so both sides round identically.
#pragma OPENCL FP_CONTRACT OFF

// The key type, set by the host at compilation: uint for 30-bit codes (half the bytes to sort and
// to read in the climb), ulong for 63-bit codes. KEY_BITS is its width.
#ifndef KEY
#define KEY ulong
#define KEY_BITS 64
#endif

// 32 bytes, as LbvhNode in lbvh_layout.h. A child >= 0 is an internal node, a child < 0 is the
// leaf ~child (the sorted primitive slot). Written by build_hierarchy.
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

// A primitive's centre, as BBox::center computes it (0.5 lo + 0.5 hi, no contraction): the
// kernels read the boxes, so no array of centres is made for them.
float3 box_center(__global const float* bounds, uint i) {
  __global const float* b = bounds + 6 * i;
  return (float3)(0.5f * b[0] + 0.5f * b[3], 0.5f * b[1] + 0.5f * b[4], 0.5f * b[2] + 0.5f * b[5]);
}

// Stage 1: centroid bounds. Work-item g reduces centres g, g + G, g + 2G, ... into six floats
// partial[6g .. 6g + 5] = (lo.x, lo.y, lo.z, hi.x, hi.y, hi.z); the host reduces the G partials.
__kernel void centroid_bounds(__global const float* prim_bounds, uint n, __global float* partial) {
  const uint g = get_global_id(0), stride = get_global_size(0);
  float lx = INFINITY, ly = INFINITY, lz = INFINITY, hx = -INFINITY, hy = -INFINITY, hz = -INFINITY;
  for (uint i = g; i < n; i += stride) {
    const float3 c = box_center(prim_bounds, i);
    lx = fmin(lx, c.x);
    ly = fmin(ly, c.y);
    lz = fmin(lz, c.z);
    hx = fmax(hx, c.x);
    hy = fmax(hy, c.y);
    hz = fmax(hz, c.z);
  }
  partial[6 * g] = lx;
  partial[6 * g + 1] = ly;
  partial[6 * g + 2] = lz;
  partial[6 * g + 3] = hx;
  partial[6 * g + 4] = hy;
  partial[6 * g + 5] = hz;
}

// Spreads the low 21 bits of v so that two zero bits separate each (bit k moves to 3k): five
// shift-or-mask steps, each moving groups half as wide as the step before, instead of a loop over
// the bits (which made this kernel cost as much as a radix pass). The same codes as a loop gives.
ulong spread_bits(ulong v) {
  v &= 0x1FFFFFUL;
  v = (v | v << 32) & 0x1F00000000FFFFUL;
  v = (v | v << 16) & 0x1F0000FF0000FFUL;
  v = (v | v << 8) & 0x100F00F00F00F00FUL;
  v = (v | v << 4) & 0x10C30C30C30C30C3UL;
  v = (v | v << 2) & 0x1249249249249249UL;
  return v;
}

// Stage 2: Morton codes of the centres, quantised to 2^bits_per_axis cells per axis of the
// centroid box. `scale` is cells / extent per axis, computed once by the host (0 for a flat axis).
__kernel void morton_codes(__global const float* prim_bounds, uint n, float lo_x, float lo_y, float lo_z, float scale_x,
                           float scale_y, float scale_z, uint bits_per_axis, __global KEY* keys,
                           __global uint* values) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const float cells = (float)((1u << bits_per_axis) - 1u);
  const float3 c = box_center(prim_bounds, i);
  const float qx = fmin(fmax((c.x - lo_x) * scale_x, 0.0f), cells);
  const float qy = fmin(fmax((c.y - lo_y) * scale_y, 0.0f), cells);
  const float qz = fmin(fmax((c.z - lo_z) * scale_z, 0.0f), cells);
  keys[i] = (KEY)((spread_bits((ulong)qx) << 2) | (spread_bits((ulong)qy) << 1) | spread_bits((ulong)qz));
  values[i] = i;
}

// Stage 3: a stable least-significant-digit radix sort of (key, value) pairs, 8 bits per pass.
// The input is cut into blocks of `block` pairs, one work-item each, walked in order, which is
// what keeps equal keys in index order (the tie-break build_hierarchy relies on).
// hist is digit-major: hist[digit * blocks + b] counts `digit` in block b, so one exclusive scan
// of it gives every (digit, block) its first output slot.
__kernel void radix_histogram(__global const KEY* keys, uint n, uint shift, uint block, __global uint* hist) {
  const uint b = get_global_id(0), blocks = get_global_size(0);
  uint count[256];
  for (uint d = 0; d < 256; ++d) count[d] = 0;
  const uint end = min(n, (b + 1) * block);
  for (uint i = b * block; i < end; ++i) ++count[(keys[i] >> shift) & 255u];
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

__kernel void radix_scatter(__global const KEY* keys_in, __global const uint* values_in, uint n, uint shift, uint block,
                            __global const uint* offsets, __global KEY* keys_out, __global uint* values_out) {
  const uint b = get_global_id(0), blocks = get_global_size(0);
  uint next[256];
  for (uint d = 0; d < 256; ++d) next[d] = offsets[d * blocks + b];
  const uint end = min(n, (b + 1) * block);
  for (uint i = b * block; i < end; ++i) {
    const KEY k = keys_in[i];
    const uint slot = next[(k >> shift) & 255u]++;
    keys_out[slot] = k;
    values_out[slot] = values_in[i];
  }
}

// Length of the common prefix of sorted keys i and j; -1 outside [0, n). Equal keys (duplicate
// Morton codes) are told apart by their indices, as if each key were followed by its index:
// Karras' tie-break, which keeps the hierarchy a valid binary tree when centroids coincide.
int common_prefix(__global const KEY* keys, long n, long i, long j) {
  if (j < 0 || j >= n) return -1;
  const KEY a = keys[i], b = keys[j];
  if (a == b) return KEY_BITS + (int)clz((uint)(i ^ j));
  return (int)clz(a ^ b);
}

// A child's box: an internal node's from the climb below, a leaf's from the input boxes through
// the sort's permutation. Reading them in place (rather than first gathering the leaves' boxes into
// sorted order) spares a pass and 24 bytes a primitive of fresh memory: Morton order keeps the
// reads near one another on meshes, whose triangles are mostly stored near their neighbours.
void child_bounds(__global const float* prim_bounds, __global const uint* values, volatile __global LbvhNode* nodes,
                  int child, float* lo, float* hi) {
  if (child < 0) {
    __global const float* b = prim_bounds + 6 * values[~child];
    for (int a = 0; a < 3; ++a) {
      lo[a] = b[a];
      hi[a] = b[3 + a];
    }
  } else {
    for (int a = 0; a < 3; ++a) {
      lo[a] = nodes[child].lo[a];
      hi[a] = nodes[child].hi[a];
    }
  }
}

// Stage 4b: the hierarchy and its boxes in one bottom-up pass (Apetrei 2014, "Fast and Simple
// Agglomerative LBVH Construction"), the same binary radix tree Karras' top-down search finds,
// without its binary searches or a second pass for the boxes. Internal node g is the one that
// splits between sorted leaves g and g + 1. One work-item per leaf climbs: a node covering
// leaves [l, r] is the left child of node r when keys r and r + 1 share a longer prefix than
// keys l - 1 and l (its range grows to the right), else the right child of node l - 1. At each
// parent the first arrival leaves the end of its range in ends[] (stored + 1: zero means empty)
// and stops; the second, whose sibling subtree is then complete, writes the parent's box and
// range and climbs on. The work-item that completes [0, n - 1] writes the root's index.
__kernel void build_hierarchy(__global const KEY* keys, uint n_leaves, __global const float* prim_bounds,
                              __global const uint* values, volatile __global LbvhNode* nodes, __global uint2* range,
                              volatile __global int* ends, __global int* root) {
  const long k = get_global_id(0), n = n_leaves;
  if (k >= n) return;
  long l = k, r = k;
  int current = ~(int)k;
  float lo[3], hi[3];
  child_bounds(prim_bounds, values, nodes, current, lo, hi);
  while (l > 0 || r < n - 1) {
    const bool is_left = l == 0 || (r < n - 1 && common_prefix(keys, n, r, r + 1) > common_prefix(keys, n, l - 1, l));
    const long parent = is_left ? r : l - 1;
    if (is_left)
      nodes[parent].left = current;
    else
      nodes[parent].right = current;
    mem_fence(CLK_GLOBAL_MEM_FENCE);  // our child link and box are visible before we announce arrival
    const int other = atomic_xchg(&ends[parent], (int)(is_left ? l : r) + 1);
    if (other == 0) return;
    mem_fence(CLK_GLOBAL_MEM_FENCE);
    if (is_left)
      r = other - 1;
    else
      l = other - 1;
    float slo[3], shi[3];
    child_bounds(prim_bounds, values, nodes, is_left ? nodes[parent].right : nodes[parent].left, slo, shi);
    for (int a = 0; a < 3; ++a) {
      lo[a] = fmin(lo[a], slo[a]);
      hi[a] = fmax(hi[a], shi[a]);
      nodes[parent].lo[a] = lo[a];
      nodes[parent].hi[a] = hi[a];
    }
    if (range) range[parent] = (uint2)((uint)l, (uint)r);  // null when only the collapse reads the tree
    current = (int)parent;
  }
  *root = current;
}

// Stage 5: the flat BVH (native/accel/node.h layout), written on the device for the callers that
// want the binary tree itself (tests, benchmarks; a commit collapses the nodes above in place).
// Internal node g's children go to slots 1 + 2g and 2 + 2g, a unique adjacent pair; the root to
// slot 0. Beside each node, the sorted slots under it (first, count).
void write_flat(__global const LbvhNode* nodes, __global const float* prim_bounds, __global const uint* values,
                __global const uint2* range, int child, uint at, __global BvhNode* out, __global uint2* out_range) {
  BvhNode node;
  if (child >= 0) {
    for (int a = 0; a < 3; ++a) {
      node.bounds[a] = nodes[child].lo[a];
      node.bounds[3 + a] = nodes[child].hi[a];
    }
    node.first = 1u + 2u * (uint)child;
    node.count = 0u;
    out_range[at] = (uint2)(range[child].x, range[child].y - range[child].x + 1u);
  } else {
    for (int a = 0; a < 6; ++a) node.bounds[a] = prim_bounds[6 * values[~child] + a];
    node.first = (uint)~child;
    node.count = 1u;
    out_range[at] = (uint2)((uint)~child, 1u);
  }
  out[at] = node;
}

__kernel void write_bvh_nodes(__global const LbvhNode* nodes, __global const float* prim_bounds,
                              __global const uint* values, __global const uint2* range, uint n_leaves, int root,
                              __global BvhNode* out, __global uint2* out_range) {
  const int g = (int)get_global_id(0);
  if (g >= (int)n_leaves - 1) return;
  if (g == root) write_flat(nodes, prim_bounds, values, range, g, 0u, out, out_range);
  write_flat(nodes, prim_bounds, values, range, nodes[g].left, 1u + 2u * (uint)g, out, out_range);
  write_flat(nodes, prim_bounds, values, range, nodes[g].right, 2u + 2u * (uint)g, out, out_range);
}
