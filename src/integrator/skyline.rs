//! A sparse direct solve for the implicit integrator's preconditioner: the stiffness
//! pattern's nodes reordered by reverse Cuthill–McKee, then a skyline (envelope) Cholesky
//! factorisation A = L Lᵀ whose rows are contiguous runs of the envelope.
//!
//! Why written here rather than taken from a crate: `nalgebra-sparse`'s `CscCholesky` does no
//! fill-reducing ordering and says itself that it is not meant for serious use, and `faer`
//! (the serious one) would add minutes to a 2-core build. An envelope factor after RCM is the
//! textbook fit for meshes that are long in one direction (beams, ropes, cloth strips); it is
//! tested against nalgebra's dense Cholesky.
//!
//! Fill: the envelope of row i runs from its first non-zero column to the diagonal, and L
//! fills exactly that envelope, so the memory is the profile Σᵢ (i − fᵢ + 1) and the work
//! about Σᵢ (i − fᵢ)², a bandwidth b costing n b² / 2.

// Rows, columns and permutations walked by one index together.
#![allow(clippy::needless_range_loop)]

use glam::{DMat3, DVec3};

/// Reverse Cuthill–McKee order of a graph given as sorted adjacency lists (`adjacency[i]`
/// holds i's neighbours, i itself allowed). Returns `order` with `order[k]` the node placed
/// k-th. Each connected component starts from a pseudo-peripheral node (two breadth-first
/// sweeps from a node of least degree), so a long mesh is numbered along its length.
#[must_use]
pub(crate) fn reverse_cuthill_mckee(adjacency: &[Vec<u32>]) -> Vec<u32> {
    let n = adjacency.len();
    let degree = |i: usize| adjacency[i].len();
    let mut placed = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut level = vec![u32::MAX; n];
    // The last node a breadth-first sweep from `start` reaches (one of its farthest).
    let farthest = |start: usize, level: &mut Vec<u32>| {
        let mut queue = vec![start];
        level[start] = 0;
        let mut head = 0;
        let mut touched = vec![start];
        while head < queue.len() {
            let i = queue[head] as usize;
            head += 1;
            for &j in &adjacency[i] {
                let j = j as usize;
                if level[j] == u32::MAX {
                    level[j] = level[i] + 1;
                    queue.push(j);
                    touched.push(j);
                }
            }
        }
        let last = *queue.last().unwrap_or(&start);
        for t in touched {
            level[t] = u32::MAX;
        }
        last as usize
    };
    let mut seeds: Vec<usize> = (0..n).collect();
    seeds.sort_by_key(|&i| (degree(i), i));
    for seed in seeds {
        if placed[seed] {
            continue;
        }
        let start = farthest(farthest(seed, &mut level), &mut level);
        let first = order.len();
        order.push(start as u32);
        placed[start] = true;
        let mut head = first;
        let mut next: Vec<u32> = Vec::new();
        while head < order.len() {
            let i = order[head] as usize;
            head += 1;
            next.clear();
            next.extend(
                adjacency[i]
                    .iter()
                    .copied()
                    .filter(|&j| !placed[j as usize]),
            );
            next.sort_by_key(|&j| (degree(j as usize), j));
            for &j in &next {
                placed[j as usize] = true;
                order.push(j);
            }
        }
    }
    order.reverse();
    order
}

/// L of A = L Lᵀ over 3 × 3 node blocks, in the RCM order, stored by rows of its envelope.
/// Read from a file (a snapshot) its structure is checked (see [`FactorRecord`]): a factor
/// one number short would index out of bounds in the next solve.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Default)]
#[serde(try_from = "FactorRecord")]
pub(crate) struct SkylineCholesky {
    /// `order[k]`: the node whose three unknowns are rows 3k..3k+3.
    order: Vec<u32>,
    /// `rank[node]`: the inverse of `order`.
    rank: Vec<u32>,
    /// Row r's first column.
    first: Vec<u32>,
    /// Row r's entries (columns first[r]..=r) start at `start[r]` in `values`.
    start: Vec<usize>,
    values: Vec<f64>,
    /// Whether `values` holds a valid factor.
    factored: bool,
    /// Counts the factorisations, so that what was derived from a factor can tell it is stale.
    generation: u64,
    /// Multiply-adds of one factorisation (Σ row length² / 2) and of one solve (2 × entries).
    factor_cost: f64,
    solve_cost: f64,
    /// The step h (s) of the system matrix M/h² + K + D/h this factors (0 before the first).
    #[serde(default)]
    pub(crate) step: f32,
}

/// [`SkylineCholesky`] as a file holds it.
#[derive(serde::Deserialize)]
pub(crate) struct FactorRecord {
    order: Vec<u32>,
    rank: Vec<u32>,
    first: Vec<u32>,
    start: Vec<usize>,
    values: Vec<f64>,
    factored: bool,
    generation: u64,
    factor_cost: f64,
    solve_cost: f64,
    #[serde(default)]
    step: f32,
}

impl TryFrom<FactorRecord> for SkylineCholesky {
    type Error = String;

    /// The order a permutation with `rank` its inverse, three rows per node, each row's first
    /// column at or before it, and the rows packed end to end in `values`.
    fn try_from(r: FactorRecord) -> Result<Self, String> {
        let n = r.order.len();
        let bad = |what: &str| Err(format!("implicit factor: {what}"));
        if r.rank.len() != n {
            return bad("rank and order differ in length");
        }
        for (k, &node) in r.order.iter().enumerate() {
            if node as usize >= n || r.rank[node as usize] as usize != k {
                return bad("order is not a permutation with rank its inverse");
            }
        }
        let rows = 3 * n;
        if r.first.len() != rows || r.start.len() != rows + 1 {
            return bad("not three rows per node");
        }
        let mut next = 0usize;
        for row in 0..rows {
            let first = r.first[row] as usize;
            if first > row || r.start[row] != next {
                return bad("rows not packed end to end");
            }
            next += row - first + 1;
        }
        if r.start[rows] != next || r.values.len() != next {
            return bad("values do not fill the envelope");
        }
        if !(r.factor_cost.is_finite() && r.solve_cost.is_finite() && r.step.is_finite()) {
            return bad("non-finite costs or step");
        }
        Ok(Self {
            order: r.order,
            rank: r.rank,
            first: r.first,
            start: r.start,
            values: r.values,
            factored: r.factored,
            generation: r.generation,
            factor_cost: r.factor_cost,
            solve_cost: r.solve_cost,
            step: r.step,
        })
    }
}

impl SkylineCholesky {
    /// How many nodes it orders.
    pub(crate) fn nodes(&self) -> usize {
        self.order.len()
    }

    /// The envelope of the matrix whose non-zero 3 × 3 blocks are the node pairs of
    /// `adjacency` (symmetric, each list sorted); None when it would hold more than
    /// `max_entries` numbers.
    #[must_use]
    pub(crate) fn new(adjacency: &[Vec<u32>], max_entries: usize) -> Option<Self> {
        let order = reverse_cuthill_mckee(adjacency);
        let mut rank = vec![0u32; order.len()];
        for (k, &i) in order.iter().enumerate() {
            rank[i as usize] = k as u32;
        }
        let rows = 3 * order.len();
        let mut first = vec![0u32; rows];
        let mut start = vec![0usize; rows + 1];
        for k in 0..order.len() {
            let lowest = adjacency[order[k] as usize]
                .iter()
                .map(|&j| rank[j as usize])
                .chain([k as u32])
                .min()
                .unwrap_or(k as u32);
            for c in 0..3 {
                let r = 3 * k + c;
                first[r] = 3 * lowest;
                start[r + 1] = start[r] + (r - first[r] as usize + 1);
            }
        }
        if start[rows] > max_entries {
            return None;
        }
        let entries = start[rows];
        let factor_cost = (0..rows)
            .map(|r| ((r - first[r] as usize + 1) as f64).powi(2) / 2.0)
            .sum();
        Some(Self {
            order,
            rank,
            first,
            start,
            values: vec![0.0; entries],
            factored: false,
            generation: 0,
            factor_cost,
            solve_cost: 2.0 * entries as f64,
            step: 0.0,
        })
    }

    /// How many solves cost as much as one factorisation.
    #[must_use]
    pub(crate) fn solves_per_factor(&self) -> f64 {
        self.factor_cost / self.solve_cost.max(1.0)
    }

    /// Whether a factor is held (the last [`Self::factor`] succeeded).
    #[must_use]
    pub(crate) fn is_factored(&self) -> bool {
        self.factored
    }

    /// Which factorisation is held (changes with every [`Self::factor`]).
    #[must_use]
    pub(crate) fn generation(&self) -> u64 {
        self.generation
    }

    /// Factors the matrix that `fill` writes: it receives a callback `add(i, j, block)` to call
    /// for every non-zero block A_ij (i, j nodes; several calls to one block add up; only the
    /// blocks with rank(i) ≥ rank(j) — the lower triangle in the new order — are kept, so `fill`
    /// may pass both or one of each symmetric pair as long as it passes the lower one).
    /// Returns false when A is not positive definite.
    pub(crate) fn factor(&mut self, fill: impl FnOnce(&mut dyn FnMut(u32, u32, DMat3))) -> bool {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        {
            let (rank, first, start, values) =
                (&self.rank, &self.first, &self.start, &mut self.values);
            let mut add = |i: u32, j: u32, block: DMat3| {
                let (ri, rj) = (rank[i as usize] as usize, rank[j as usize] as usize);
                if ri < rj {
                    return;
                }
                for a in 0..3 {
                    let row = 3 * ri + a;
                    for b in 0..3 {
                        let col = 3 * rj + b;
                        if col > row {
                            continue;
                        }
                        debug_assert!(col >= first[row] as usize);
                        values[start[row] + col - first[row] as usize] += block.col(b)[a];
                    }
                }
            };
            fill(&mut add);
        }
        self.generation += 1;
        self.factored = self.decompose();
        self.factored
    }

    fn decompose(&mut self) -> bool {
        let rows = self.first.len();
        for i in 0..rows {
            let fi = self.first[i] as usize;
            let si = self.start[i];
            for j in fi..i {
                let fj = self.first[j] as usize;
                let sj = self.start[j];
                let lo = fi.max(fj);
                let (row_i, row_j) = (
                    &self.values[si + lo - fi..si + j - fi],
                    &self.values[sj + lo - fj..sj + j - fj],
                );
                let dot = dot(row_i, row_j);
                let diag = self.values[sj + j - fj];
                let v = &mut self.values[si + j - fi];
                *v = (*v - dot) / diag;
            }
            let row = &self.values[si..si + i - fi];
            let d = self.values[si + i - fi] - dot(row, row);
            if !(d > 0.0 && d.is_finite()) {
                return false;
            }
            self.values[si + i - fi] = d.sqrt();
        }
        true
    }

    /// z = A⁻¹ r with the held factor; `work` is scratch of any content.
    pub(crate) fn solve(&self, r: &[DVec3], z: &mut [DVec3], work: &mut Vec<f64>) {
        let rows = self.first.len();
        work.clear();
        work.resize(rows, 0.0);
        for (k, &node) in self.order.iter().enumerate() {
            let v = r[node as usize];
            work[3 * k..3 * k + 3].copy_from_slice(&v.to_array());
        }
        // L y = r
        for i in 0..rows {
            let (fi, si) = (self.first[i] as usize, self.start[i]);
            let row = &self.values[si..si + i - fi];
            let dot = dot(row, &work[fi..i]);
            work[i] = (work[i] - dot) / self.values[si + i - fi];
        }
        // Lᵀ x = y
        for i in (0..rows).rev() {
            let (fi, si) = (self.first[i] as usize, self.start[i]);
            let xi = work[i] / self.values[si + i - fi];
            work[i] = xi;
            for (k, a) in self.values[si..si + i - fi].iter().enumerate() {
                work[fi + k] -= a * xi;
            }
        }
        for (k, &node) in self.order.iter().enumerate() {
            z[node as usize] = DVec3::from_slice(&work[3 * k..3 * k + 3]);
        }
    }
}

/// Σ aᵢ bᵢ with four running sums: a single sum waits on each addition (its latency), four
/// let the additions overlap and vectorise. The order is fixed, so results stay bit-identical
/// from run to run.
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += x * y;
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    type Blocks = Vec<(u32, u32, DMat3)>;

    /// A path graph 0–1–…–(n−1) numbered out of order, with blocks that make an SPD matrix.
    fn scrambled_chain(n: usize) -> (Vec<Vec<u32>>, Blocks) {
        let label = |k: usize| ((k * 7) % n) as u32; // 7 is coprime to the sizes used
        let mut adj = vec![Vec::new(); n];
        let mut blocks = Vec::new();
        for k in 0..n {
            let i = label(k);
            adj[i as usize].push(i);
            let d = DMat3::from_cols(
                DVec3::new(4.0, 0.5, 0.0),
                DVec3::new(0.5, 5.0, 0.2),
                DVec3::new(0.0, 0.2, 6.0),
            );
            blocks.push((i, i, d));
            if k + 1 < n {
                let j = label(k + 1);
                adj[i as usize].push(j);
                adj[j as usize].push(i);
                let off = DMat3::from_cols(
                    DVec3::new(-1.0, 0.1, 0.0),
                    DVec3::new(0.3, -1.0, 0.0),
                    DVec3::new(0.0, 0.0, -1.0),
                );
                blocks.push((i, j, off));
                blocks.push((j, i, off.transpose()));
            }
        }
        for a in &mut adj {
            a.sort_unstable();
        }
        (adj, blocks)
    }

    #[test]
    fn rcm_numbers_a_scrambled_chain_along_its_length() {
        let (adj, _) = scrambled_chain(50);
        let order = reverse_cuthill_mckee(&adj);
        let mut rank = [0usize; 50];
        for (k, &i) in order.iter().enumerate() {
            rank[i as usize] = k;
        }
        for (i, list) in adj.iter().enumerate() {
            for &j in list {
                assert!(rank[i].abs_diff(rank[j as usize]) <= 1, "bandwidth > 1");
            }
        }
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..50).collect::<Vec<u32>>());
    }

    #[test]
    fn solve_matches_nalgebra_dense_cholesky() {
        let n = 30;
        let (adj, blocks) = scrambled_chain(n);
        let mut dense = DMatrix::<f64>::zeros(3 * n, 3 * n);
        for &(i, j, b) in &blocks {
            for a in 0..3 {
                for c in 0..3 {
                    dense[(3 * i as usize + a, 3 * j as usize + c)] += b.col(c)[a];
                }
            }
        }
        let mut f = SkylineCholesky::new(&adj, usize::MAX).unwrap();
        assert!(f.factor(|add| {
            for &(i, j, b) in &blocks {
                add(i, j, b);
            }
        }));
        let r: Vec<DVec3> = (0..n)
            .map(|k| DVec3::new(k as f64, 1.0 - k as f64 * 0.3, (k as f64).sin()))
            .collect();
        let mut z = vec![DVec3::ZERO; n];
        f.solve(&r, &mut z, &mut Vec::new());
        let rhs = nalgebra::DVector::from_iterator(3 * n, r.iter().flat_map(|v| v.to_array()));
        let exact = dense.cholesky().unwrap().solve(&rhs);
        for k in 0..n {
            for c in 0..3 {
                assert!((z[k][c] - exact[3 * k + c]).abs() < 1e-12, "{k} {c}");
            }
        }
    }

    #[test]
    fn an_indefinite_matrix_is_refused() {
        let (adj, blocks) = scrambled_chain(5);
        let mut f = SkylineCholesky::new(&adj, usize::MAX).unwrap();
        assert!(!f.factor(|add| {
            for &(i, j, b) in &blocks {
                add(i, j, if i == j { -b } else { b });
            }
        }));
        assert!(!f.is_factored());
        assert!(SkylineCholesky::new(&adj, 10).is_none(), "over the cap");
    }
}
