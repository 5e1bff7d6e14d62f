//! Exact minimisation of a binary labelling energy with submodular pairwise terms by an s-t
//! minimum cut (Kolmogorov & Zabih 2004, "What energy functions can be minimized via graph
//! cuts?", IEEE PAMI 26(2)); max flow by Dinic's algorithm.
//!
//! A pairwise term `E(xa, xb)` with table `A = E(0,0), B = E(0,1), C = E(1,0), D = E(1,1)` is
//! `A + (C - A) xa + (D - C) xb + (B + C - A - D) (1 - xa) xb`; the last coefficient must be
//! non-negative (submodularity) and becomes the capacity of edge a -> b. Unary terms become
//! source or sink edges. Nodes on the sink side after the cut take label 1.

/// A binary energy under construction.
pub struct Energy {
    n: usize,
    /// Unary costs of label 0 and label 1 per node.
    unary: Vec<[f64; 2]>,
    pairs: Vec<(usize, usize, f64)>,
    constant: f64,
}

impl Energy {
    pub fn new(n: usize) -> Energy {
        Energy {
            n,
            unary: vec![[0.0; 2]; n],
            pairs: vec![],
            constant: 0.0,
        }
    }

    pub fn add_unary(&mut self, a: usize, cost0: f64, cost1: f64) {
        self.unary[a][0] += cost0;
        self.unary[a][1] += cost1;
    }

    /// Add `E(xa, xb)` given as `[E00, E01, E10, E11]`. Panics in debug builds if it is not
    /// submodular (a programming error, not an input error).
    pub fn add_pair(&mut self, a: usize, b: usize, e: [f64; 4]) {
        let [a0, b0, c0, d0] = e;
        let w = b0 + c0 - a0 - d0;
        debug_assert!(w >= -1e-9, "non-submodular term {e:?}");
        self.constant += a0;
        self.add_unary(a, 0.0, c0 - a0);
        self.add_unary(b, 0.0, d0 - c0);
        if w > 0.0 {
            self.pairs.push((a, b, w));
        }
    }

    /// The minimising labels and the minimum energy.
    pub fn minimise(&self) -> (Vec<bool>, f64) {
        let (s, t) = (self.n, self.n + 1);
        let mut g = Dinic::new(self.n + 2);
        let mut constant = self.constant;
        for (i, u) in self.unary.iter().enumerate() {
            let m = u[0].min(u[1]);
            constant += m;
            // Label 1 = sink side: cutting s->i costs u1, cutting i->t costs u0.
            if u[1] - m > 0.0 {
                g.add(s, i, u[1] - m);
            }
            if u[0] - m > 0.0 {
                g.add(i, t, u[0] - m);
            }
        }
        for &(a, b, w) in &self.pairs {
            g.add(a, b, w);
        }
        let flow = g.max_flow(s, t);
        let source_side = g.reachable(s);
        let labels = (0..self.n).map(|i| !source_side[i]).collect();
        (labels, constant + flow)
    }
}

struct Dinic {
    adj: Vec<Vec<usize>>,
    to: Vec<usize>,
    cap: Vec<f64>,
}

impl Dinic {
    fn new(n: usize) -> Dinic {
        Dinic {
            adj: vec![vec![]; n],
            to: vec![],
            cap: vec![],
        }
    }
    fn add(&mut self, a: usize, b: usize, c: f64) {
        self.adj[a].push(self.to.len());
        self.to.push(b);
        self.cap.push(c);
        self.adj[b].push(self.to.len());
        self.to.push(a);
        self.cap.push(0.0);
    }
    fn levels(&self, s: usize) -> Vec<i64> {
        let mut lv = vec![-1; self.adj.len()];
        lv[s] = 0;
        let mut q = std::collections::VecDeque::from([s]);
        while let Some(u) = q.pop_front() {
            for &e in &self.adj[u] {
                if self.cap[e] > 1e-12 && lv[self.to[e]] < 0 {
                    lv[self.to[e]] = lv[u] + 1;
                    q.push_back(self.to[e]);
                }
            }
        }
        lv
    }
    fn push(&mut self, u: usize, t: usize, f: f64, lv: &[i64], it: &mut [usize]) -> f64 {
        if u == t {
            return f;
        }
        while it[u] < self.adj[u].len() {
            let e = self.adj[u][it[u]];
            let v = self.to[e];
            if self.cap[e] > 1e-12 && lv[v] == lv[u] + 1 {
                let d = self.push(v, t, f.min(self.cap[e]), lv, it);
                if d > 0.0 {
                    self.cap[e] -= d;
                    self.cap[e ^ 1] += d;
                    return d;
                }
            }
            it[u] += 1;
        }
        0.0
    }
    fn max_flow(&mut self, s: usize, t: usize) -> f64 {
        let mut flow = 0.0;
        loop {
            let lv = self.levels(s);
            if lv[t] < 0 {
                return flow;
            }
            let mut it = vec![0; self.adj.len()];
            loop {
                let f = self.push(s, t, f64::INFINITY, &lv, &mut it);
                if f <= 0.0 {
                    break;
                }
                flow += f;
            }
        }
    }
    fn reachable(&self, s: usize) -> Vec<bool> {
        self.levels(s).iter().map(|&l| l >= 0).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force over all labellings as the oracle.
    #[test]
    fn agrees_with_brute_force_on_random_submodular_energies() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        for _ in 0..200 {
            let n = rng.random_range(1..8);
            let mut e = Energy::new(n);
            let mut terms = vec![];
            for i in 0..n {
                let u = [rng.random::<f64>(), rng.random::<f64>()];
                e.add_unary(i, u[0], u[1]);
                terms.push((i, i, [u[0], u[1], 0.0, 0.0]));
            }
            for _ in 0..n * 2 {
                let (a, b) = (rng.random_range(0..n), rng.random_range(0..n));
                if a == b {
                    continue;
                }
                let (a0, d0): (f64, f64) = (rng.random(), rng.random());
                let b0: f64 = rng.random();
                let c0 = (a0 + d0 - b0).max(0.0) + rng.random::<f64>();
                e.add_pair(a, b, [a0, b0, c0, d0]);
                terms.push((a, b, [a0, b0, c0, d0]));
            }
            let eval = |x: &[bool]| -> f64 {
                terms
                    .iter()
                    .map(|&(a, b, t)| {
                        if a == b {
                            t[x[a] as usize]
                        } else {
                            t[(x[a] as usize) * 2 + x[b] as usize]
                        }
                    })
                    .sum()
            };
            let best = (0..1u32 << n)
                .map(|m| eval(&(0..n).map(|i| m >> i & 1 == 1).collect::<Vec<_>>()))
                .fold(f64::INFINITY, f64::min);
            let (x, v) = e.minimise();
            assert!(
                (v - best).abs() < 1e-9 && (eval(&x) - best).abs() < 1e-9,
                "{v} {best}"
            );
        }
    }
}
