//! The binary BVH (obvhs's `Bvh2`, one primitive per leaf) turned into the compressed 8-wide
//! BVH (CWBVH) that traversal walks, on every core.
//!
//! The nodes are exactly those of obvhs 0.4's serial `bvh2_to_cwbvh` (children ordered by
//! octant, no exact node boxes): the wide tree
//! is stored in compiled scenes under `GEOMETRY_REVISION`, so it must not depend on who
//! converts it, nor on the thread count. The unit tests compare the two node for node.
//! This conversion was a quarter of the CPU time of loading 1M triangles, all on one core
//! (issue 18).
//!
//! Method (Ylitie, Karras & Laine 2017, "Efficient incoherent ray traversal on GPUs through
//! compressed wide BVHs", HPG; the table layout follows obvhs):
//!
//! 1. **Costs, bottom-up.** For each binary node `n` and `i` in 0..7, `c(n, i)` is the
//!    least surface-area cost of standing for `n`'s subtree with at most `i + 1` children of
//!    a wide node. A leaf costs `0.3 · area/2` whatever `i`. For an inner node with
//!    children `a`, `b`: at `i = 0` either one wide leaf (`0.3 · prims · area/2`, up to
//!    `max_leaf` primitives) or a wide node of its own (`area/2 + min_k c(a, k) + c(b, 6 − k)`),
//!    whichever is cheaper (ties: the node); for `i ≥ 1`, the cheaper of `c(n, i − 1)` and
//!    splitting the `i + 1` slots between the two children (`min_k c(a, k) + c(b, i − 1 − k)`,
//!    the node itself then "distributes" its children upwards). The lowest `k` wins ties,
//!    as in obvhs. Subtrees are independent, so the two children run in parallel near the
//!    root. The same pass counts, for each choice, how many wide nodes and primitives the
//!    subtree will produce (the counts follow the same decisions the next pass follows).
//! 2. **Layout, top-down.** A serial depth-first conversion appends, at each wide node, the
//!    block of its inner children, then converts the children one after another; so every
//!    wide subtree occupies one contiguous range of nodes (and of primitive indices) whose
//!    length pass 1 knows. The output is split into those disjoint ranges and the subtrees
//!    written in parallel, each at the index the serial conversion gives it.
//! 3. **Encoding** (the paper's compressed node): a node keeps its box's minimum `p` and, per
//!    axis, a power-of-two scale `2^e ≥ extent / 255`; each child's box is stored as 8-bit
//!    multiples of it, rounded outwards. Children are placed in the eight slots greedily
//!    by the octant their centre lies in from the node's centre (cheapest slot first), so
//!    that a ray visits them near to far from its direction's octant.
//!
//! Every floating-point operation is obvhs's, in its order (`f32`, no fused multiply-add),
//! so the bytes agree.

use std::sync::atomic::{AtomicU64, Ordering};

use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::node::CwBvhNode;

/// Weight of a primitive test against a node visit in the cost (obvhs's `PRIM_COST`).
const PRIM_COST: f32 = 0.3;

/// The quantisation step of child boxes, 1/255 of the scale (obvhs's `DENOM`).
const DENOM: f32 = 1.0 / 255.0;

/// Binary levels below which pass 1 stops splitting work between threads.
const PAR_DEPTH: u32 = 12;

/// Wide subtrees of fewer primitives are written by one thread.
const PAR_PRIMS: usize = 1 << 13;

const LEAF: u8 = 0;
const INNER: u8 = 1;
const DISTRIBUTE: u8 = 2;
/// "No split found" (obvhs's `u8::MAX`); only non-finite costs leave it.
const NONE: u8 = 7;

/// One table entry: what node `n` does with `i + 1` slots, and how it splits them
/// between its children (`left + right = i − 1` when distributing).
#[derive(Clone, Copy)]
struct Decision {
    kind: u8,
    left: u8,
    right: u8,
}

impl Decision {
    fn pack(self) -> u8 {
        self.kind | self.left << 2 | self.right << 5
    }

    fn unpack(b: u8) -> Decision {
        Decision {
            kind: b & 3,
            left: (b >> 2) & 7,
            right: b >> 5,
        }
    }
}

/// Pass 1's answer for one binary subtree.
struct Sub {
    cost: [f32; 7],
    /// The seven decisions, one byte each (see [`Decision::pack`]).
    table: u64,
    /// Wide nodes made by the children this subtree yields with `i + 1` slots.
    wide: [u32; 7],
    prims: u32,
}

impl Sub {
    fn decision(&self, i: usize) -> Decision {
        Decision::unpack((self.table >> (8 * i)) as u8)
    }

    /// Wide nodes this subtree adds when its parent, splitting slots, gives it `i + 1`:
    /// as many as its own children make if it distributes, else none (it is a leaf child)
    /// or itself and its wide subtree (it is an inner child).
    fn wide_as_child(&self, i: usize) -> u32 {
        if self.decision(i).kind == DISTRIBUTE {
            self.wide[i]
        } else if self.decision(0).kind == INNER {
            1 + self.wide[0]
        } else {
            0
        }
    }
}

/// A wide subtree to write.
struct Job<'a> {
    /// Its binary node.
    n: usize,
    /// Its own node (in its parent's block of children).
    own: &'a mut CwBvhNode,
    /// The nodes below it, and the index of the first.
    below: &'a mut [CwBvhNode],
    start: u32,
    /// Its primitives, and the index of the first.
    prims: &'a mut [u32],
    prim_start: u32,
}

struct Converter<'a> {
    bvh2: &'a Bvh2,
    max_leaf: u32,
    /// Per binary node: its seven decisions (leaves: all zero, i.e. leaf).
    table: Vec<AtomicU64>,
    /// Per inner binary node: wide nodes below it as a wide node (high half) and its
    /// primitives (low half).
    counts: Vec<AtomicU64>,
}

/// The CWBVH of `bvh2` with wide leaves of at most `max_leaf` (1 to 3) primitives, node for
/// node what obvhs's `bvh2_to_cwbvh(bvh2, max_leaf, true, false)` makes, for any number of
/// threads.
///
/// Panics where obvhs does: a binary leaf of more than one primitive.
pub fn bvh2_to_cwbvh(bvh2: &Bvh2, max_leaf: u32) -> CwBvh {
    assert!(
        (1..=3).contains(&max_leaf),
        "wide leaves hold 1 to 3 primitives"
    );
    if bvh2.nodes.is_empty() {
        return CwBvh::default();
    }
    let zeros = |n: usize| (0..n).map(|_| AtomicU64::new(0)).collect::<Vec<_>>();
    let c = Converter {
        bvh2,
        max_leaf,
        table: zeros(bvh2.nodes.len()),
        counts: zeros(bvh2.nodes.len()),
    };
    let root = c.costs(0, 0);
    let mut nodes = vec![CwBvhNode::default(); 1 + root.wide[0] as usize];
    let mut prims = vec![0u32; root.prims as usize];
    let (first, rest) = nodes.split_first_mut().expect("one node at least");
    let job = Job {
        n: 0,
        own: first,
        below: rest,
        start: 1,
        prims: &mut prims,
        prim_start: 0,
    };
    rayon::scope(|scope| c.write(scope, job));
    CwBvh {
        nodes,
        primitive_indices: prims,
        total_aabb: *bvh2.nodes[0].aabb(),
        exact_node_aabbs: None,
        uses_spatial_splits: bvh2.uses_spatial_splits,
    }
}

impl Converter<'_> {
    /// Pass 1 over the subtree of binary node `n` (see the module documentation): the two
    /// children in parallel down to [`PAR_DEPTH`], then one thread per subtree.
    fn costs(&self, n: usize, depth: u32) -> Sub {
        let node = &self.bvh2.nodes[n];
        if node.is_leaf() || depth >= PAR_DEPTH {
            return self.costs_serial(n);
        }
        let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
        let (a, b) = rayon::join(|| self.costs(l, depth + 1), || self.costs(r, depth + 1));
        self.combine(n, &a, &b)
    }

    /// Pass 1 over a subtree without recursion (a binary tree can be thousands of levels
    /// deep where many boxes coincide): children before parents, their answers on a stack.
    fn costs_serial(&self, root: usize) -> Sub {
        let mut todo = vec![(root, false)];
        let mut done: Vec<Sub> = Vec::new();
        while let Some((n, children_done)) = todo.pop() {
            let node = &self.bvh2.nodes[n];
            if node.is_leaf() {
                assert_eq!(
                    node.prim_count, 1,
                    "the wide BVH is made from leaves of one primitive"
                );
                done.push(Sub {
                    cost: [node.aabb().half_area() * 1.0 * PRIM_COST; 7],
                    table: 0,
                    wide: [0; 7],
                    prims: 1,
                });
            } else if children_done {
                let b = done.pop().expect("right child done");
                let a = done.pop().expect("left child done");
                done.push(self.combine(n, &a, &b));
            } else {
                let l = node.first_index as usize;
                todo.extend([(n, true), (l + 1, false), (l, false)]);
            }
        }
        done.pop().expect("the subtree's answer")
    }

    /// Inner binary node `n`'s costs and decisions from its children's `a` and `b`.
    fn combine(&self, n: usize, a: &Sub, b: &Sub) -> Sub {
        let half_area = self.bvh2.nodes[n].aabb().half_area();
        let prims = a.prims + b.prims;
        let mut cost = [0f32; 7];
        let mut dec = [Decision {
            kind: LEAF,
            left: NONE,
            right: NONE,
        }; 7];
        // One slot: a wide leaf or a wide node of its own.
        let as_leaf = if prims <= self.max_leaf {
            (prims as f32) * half_area * PRIM_COST
        } else {
            f32::INFINITY
        };
        let mut best = f32::INFINITY;
        for k in 0..7 {
            let s = a.cost[k] + b.cost[6 - k];
            if s < best {
                best = s;
                dec[0].left = k as u8;
                dec[0].right = 6 - k as u8;
            }
        }
        let as_node = best + half_area;
        if as_leaf < as_node {
            (dec[0].kind, cost[0]) = (LEAF, as_leaf);
        } else {
            (dec[0].kind, cost[0]) = (INNER, as_node);
        }
        // More slots: as with one fewer, or the slots split between the children.
        for i in 1..7 {
            let mut best = cost[i - 1];
            let mut split = None;
            for k in 0..i {
                let s = a.cost[k] + b.cost[i - k - 1];
                if s < best {
                    best = s;
                    split = Some(k);
                }
            }
            cost[i] = best;
            dec[i] = match split {
                Some(k) => Decision {
                    kind: DISTRIBUTE,
                    left: k as u8,
                    right: (i - k - 1) as u8,
                },
                None => dec[i - 1],
            };
        }
        let mut wide = [0u32; 7];
        let mut table = 0u64;
        for i in 0..7 {
            let d = dec[i];
            if d.left < 7 && d.right < 7 {
                wide[i] = a.wide_as_child(d.left as usize) + b.wide_as_child(d.right as usize);
            }
            table |= (d.pack() as u64) << (8 * i);
        }
        self.table[n].store(table, Ordering::Relaxed);
        self.counts[n].store((wide[0] as u64) << 32 | prims as u64, Ordering::Relaxed);
        Sub {
            cost,
            table,
            wide,
            prims,
        }
    }

    fn decision(&self, n: usize, i: usize) -> Decision {
        Decision::unpack((self.table[n].load(Ordering::Relaxed) >> (8 * i)) as u8)
    }

    /// Wide nodes below inner binary node `n` made a wide node, and its primitives.
    fn counts(&self, n: usize) -> (u32, u32) {
        let c = self.counts[n].load(Ordering::Relaxed);
        ((c >> 32) as u32, c as u32)
    }

    /// The children binary node `n` yields with `i + 1` slots, appended to `out`.
    fn children(&self, n: usize, i: usize, out: &mut [u32; 8], count: &mut usize) {
        let node = &self.bvh2.nodes[n];
        if node.is_leaf() {
            out[*count] = n as u32;
            *count += 1;
            return;
        }
        let d = self.decision(n, i);
        for (c, j) in [
            (node.first_index as usize, d.left as usize),
            (node.first_index as usize + 1, d.right as usize),
        ] {
            if self.decision(c, j).kind == DISTRIBUTE {
                self.children(c, j, out, count);
            } else {
                out[*count] = c as u32;
                *count += 1;
            }
        }
    }

    /// Children into the eight slots by the octant of their centres seen from `n`'s:
    /// repeatedly the cheapest (child, free slot) pair, cost = −(offset · octant sign).
    fn order(&self, n: usize, children: &mut [u32; 8], count: usize) {
        let p = self.bvh2.nodes[n].aabb().center();
        let mut cost = [[f32::MAX; 8]; 8];
        for (c, row) in cost.iter_mut().enumerate().take(count) {
            let q = self.bvh2.nodes[children[c] as usize].aabb().center();
            let v = [q.x - p.x, q.y - p.y, q.z - p.z];
            for (s, slot) in row.iter_mut().enumerate() {
                let sign = |bit: usize| if s & bit != 0 { -1.0f32 } else { 1.0 };
                *slot = sign(4) * v[0] + sign(2) * v[1] + sign(1) * v[2];
            }
        }
        let mut slot_of = [usize::MAX; 8];
        let mut taken = [false; 8];
        loop {
            let mut min = f32::MAX;
            let mut pick = None;
            for c in 0..count {
                if slot_of[c] != usize::MAX {
                    continue;
                }
                for s in 0..8 {
                    if !taken[s] && cost[c][s] < min {
                        min = cost[c][s];
                        pick = Some((c, s));
                    }
                }
            }
            let Some((c, s)) = pick else { break };
            taken[s] = true;
            slot_of[c] = s;
        }
        let given = std::mem::replace(children, [u32::MAX; 8]);
        for c in 0..count {
            children[slot_of[c]] = given[c];
        }
    }

    /// The primitives of binary subtree `n`, left before right, into `out` from `*k`.
    fn leaf_prims(&self, n: usize, out: &mut [u32], k: &mut usize) {
        let node = &self.bvh2.nodes[n];
        if node.is_leaf() {
            out[*k] = self.bvh2.primitive_indices[node.first_index as usize];
            *k += 1;
        } else {
            self.leaf_prims(node.first_index as usize, out, k);
            self.leaf_prims(node.first_index as usize + 1, out, k);
        }
    }

    /// Pass 2 from one wide subtree: subtrees of [`PAR_PRIMS`] primitives or more are
    /// handed to other threads (all in the one scope, so nothing nests), smaller ones are
    /// written here from a work list (no recursion: wide trees can be deep too).
    fn write<'s>(&'s self, scope: &rayon::Scope<'s>, job: Job<'s>) {
        let mut todo = vec![job];
        while let Some(job) = todo.pop() {
            for child in self.write_one(job).into_iter().flatten() {
                if child.prims.len() >= PAR_PRIMS {
                    scope.spawn(move |scope| self.write(scope, child));
                } else {
                    todo.push(child);
                }
            }
        }
    }

    /// Binary node `n` as the wide node `own`, in the serial conversion's order; its
    /// inner children as jobs, each with its part of `below` (wide nodes from index
    /// `start`) and of `prims` (primitives from index `prim_start`).
    fn write_one<'s>(&self, job: Job<'s>) -> [Option<Job<'s>>; 8] {
        let Job {
            n,
            own,
            below,
            start,
            prims,
            prim_start,
        } = job;
        let aabb = self.bvh2.nodes[n].aabb();
        let (lo, hi) = (aabb.min, aabb.max);
        // Per axis the smallest power of two that spans the extent in 255 steps.
        let scale = |d: f32| (d.max(1e-20) * DENOM).log2().ceil().exp2();
        let e = [scale(hi.x - lo.x), scale(hi.y - lo.y), scale(hi.z - lo.z)];
        let rcp = [1.0 / e[0], 1.0 / e[1], 1.0 / e[2]];
        let mut node = CwBvhNode {
            p: [lo.x, lo.y, lo.z].into(),
            e: e.map(|v| (v.to_bits() >> 23) as u8),
            primitive_base_idx: prim_start,
            child_base_idx: start,
            ..Default::default()
        };

        let mut children = [u32::MAX; 8];
        let mut count = 0;
        self.children(n, 0, &mut children, &mut count);
        self.order(n, &mut children, count);

        let mut inner = [u32::MAX; 8];
        let mut ninner = 0;
        let mut nprims = 0usize;
        for (i, &c) in children.iter().enumerate() {
            if c == u32::MAX {
                continue;
            }
            let b = self.bvh2.nodes[c as usize].aabb();
            let q = |v: f32, p: f32, r: f32, up: bool| {
                let x = (v - p) * r;
                let x = if up { x.ceil() } else { x.floor() };
                x.clamp(0.0, 255.0) as u8
            };
            node.child_min_x[i] = q(b.min.x, lo.x, rcp[0], false);
            node.child_min_y[i] = q(b.min.y, lo.y, rcp[1], false);
            node.child_min_z[i] = q(b.min.z, lo.z, rcp[2], false);
            node.child_max_x[i] = q(b.max.x, lo.x, rcp[0], true);
            node.child_max_y[i] = q(b.max.y, lo.y, rcp[1], true);
            node.child_max_z[i] = q(b.max.z, lo.z, rcp[2], true);
            if self.decision(c as usize, 0).kind == INNER {
                node.imask |= 1 << i;
                node.child_meta[i] = (24 + i as u8) | 0b0010_0000;
                inner[ninner] = c;
                ninner += 1;
            } else {
                let first = nprims;
                self.leaf_prims(c as usize, prims, &mut nprims);
                // The count in unary in the top three bits, the offset below.
                node.child_meta[i] = first as u8
                    | match nprims - first {
                        1 => 0b0010_0000,
                        2 => 0b0110_0000,
                        3 => 0b1110_0000,
                        k => panic!("a wide-BVH leaf of {k} primitives"),
                    };
            }
        }
        *own = node;

        // The inner children's block, then each one's wide subtree and primitives in turn.
        let (block, mut rest) = below.split_at_mut(ninner);
        let (_, mut prest) = prims.split_at_mut(nprims);
        let mut at = start + ninner as u32;
        let mut pat = prim_start + nprims as u32;
        let mut jobs: [Option<Job>; 8] = Default::default();
        for ((slot, &c), job) in block.iter_mut().zip(&inner[..ninner]).zip(&mut jobs) {
            let (w, p) = self.counts(c as usize);
            let (sub, r) = std::mem::take(&mut rest).split_at_mut(w as usize);
            let (psub, pr) = std::mem::take(&mut prest).split_at_mut(p as usize);
            (rest, prest) = (r, pr);
            *job = Some(Job {
                n: c as usize,
                own: slot,
                below: sub,
                start: at,
                prims: psub,
                prim_start: pat,
            });
            at += w;
            pat += p;
        }
        debug_assert!(rest.is_empty() && prest.is_empty());
        jobs
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use obvhs::{BvhBuildParams, aabb::Aabb, ploc::PlocBuilder};

    /// A tiny seeded generator (the tests need varied boxes, not statistics).
    fn lcg(state: &mut u64) -> f32 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*state >> 40) as f32) / (1u64 << 24) as f32
    }

    /// Boxes of several kinds: small and scattered, flat (zero extent on an axis, as
    /// axis-aligned polygons give), long and thin, identical ones, and far apart sizes.
    fn boxes(n: usize, seed: u64) -> Vec<Aabb> {
        let mut s = seed;
        (0..n)
            .map(|k| {
                let c = [lcg(&mut s) * 10.0, lcg(&mut s) * 10.0, lcg(&mut s) * 10.0];
                let mut d = [lcg(&mut s) * 0.05, lcg(&mut s) * 0.05, lcg(&mut s) * 0.05];
                match k % 7 {
                    0 => d[(k / 7) % 3] = 0.0,
                    1 => d[0] *= 200.0,
                    2 => d = [1e-7, 2e-7, 0.0],
                    3 if k > 3 => return Aabb::new([1.0, 2.0, 3.0].into(), [1.5, 2.0, 3.5].into()),
                    _ => {}
                }
                Aabb::new(
                    [c[0] - d[0], c[1] - d[1], c[2] - d[2]].into(),
                    [c[0] + d[0], c[1] + d[1], c[2] + d[2]].into(),
                )
            })
            .collect()
    }

    fn bvh2_of(boxes: &[Aabb], params: BvhBuildParams) -> Bvh2 {
        let mut bvh2 = PlocBuilder::with_capacity(boxes.len()).build(
            params.ploc_search_distance,
            boxes,
            (0..boxes.len() as u32).collect(),
            params.sort_precision,
            params.search_depth_threshold,
        );
        obvhs::bvh2::reinsertion::ReinsertionOptimizer::default().run(
            &mut bvh2,
            params.reinsertion_batch_ratio,
            None,
        );
        bvh2
    }

    #[test]
    fn converts_node_for_node_as_obvhs() {
        let presets = [
            BvhBuildParams::fast_build(),
            BvhBuildParams::medium_build(),
            BvhBuildParams::very_fast_build(),
        ];
        for (n, seed) in [
            (1, 1),
            (2, 2),
            (3, 3),
            (4, 4),
            (9, 5),
            (100, 6),
            (5000, 7),
            (60000, 8),
        ] {
            for params in presets {
                let b = boxes(n, seed);
                let bvh2 = bvh2_of(&b, params);
                for max_leaf in [3, 1] {
                    let theirs =
                        obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(&bvh2, max_leaf, true, false);
                    // Several thread counts: the layout must not depend on who wrote what.
                    for threads in [1, 2, 5] {
                        let pool = rayon::ThreadPoolBuilder::new()
                            .num_threads(threads)
                            .build()
                            .unwrap();
                        let ours = pool.install(|| bvh2_to_cwbvh(&bvh2, max_leaf));
                        assert!(
                            ours.nodes == theirs.nodes,
                            "{n} boxes, {threads} threads: nodes differ"
                        );
                        assert_eq!(
                            ours.primitive_indices, theirs.primitive_indices,
                            "{n} boxes"
                        );
                        assert_eq!(ours.total_aabb, theirs.total_aabb);
                        assert!(ours.exact_node_aabbs.is_none());
                    }
                }
            }
        }
    }

    #[test]
    fn an_empty_tree_converts_to_an_empty_one() {
        let ours = bvh2_to_cwbvh(&Bvh2::default(), 3);
        assert!(ours.nodes.is_empty() && ours.primitive_indices.is_empty());
    }
}
