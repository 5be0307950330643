//! Complete binary tree (tournament tree) over per-disk event times.
//!
//! Leaves are disks; each internal node holds the disk with the earlier event of its two
//! children, so the root holds the disk with the earliest event. Changing one disk's event costs
//! one walk to the root, O(log N). Ties go to the lower disk number (deterministic).

/// A tournament tree over `times[0..n]`. The tree stores disk numbers only; the times live in
/// the caller's array (`times[n]` must be +∞: padding leaves point to it).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct CompleteBinaryTree {
    leaves: usize,
    node: Vec<u32>,
}

impl CompleteBinaryTree {
    /// `true` when the tree has the shape [`build`](Self::build) gives for `n` disks and points
    /// only at disks `0..=n` (a checkpoint's tree is checked before it is used).
    pub fn fits(&self, n: usize) -> bool {
        let leaves = n.max(1);
        self.leaves == leaves
            && self.node.len() == 2 * leaves
            && self.node.iter().all(|&k| k as usize <= n)
    }

    /// Builds the tree over `times[0..n]`, where `times.len() == n + 1` and `times[n] = ∞`.
    /// The tree is heap-shaped with exactly `n` leaves (node k has children 2k and 2k + 1, leaf
    /// i sits at n + i), so it needs 2n entries for any n, not 2·next_power_of_two(n).
    pub fn build(times: &[f64]) -> CompleteBinaryTree {
        let n = times.len() - 1;
        let leaves = n.max(1);
        let mut node = vec![n as u32; 2 * leaves];
        for (i, slot) in node[leaves..leaves + n].iter_mut().enumerate() {
            *slot = i as u32;
        }
        let mut tree = CompleteBinaryTree { leaves, node };
        for k in (1..leaves).rev() {
            tree.node[k] = tree.winner(times, k);
        }
        tree
    }

    #[inline(always)]
    fn winner(&self, times: &[f64], k: usize) -> u32 {
        let (l, r) = (self.node[2 * k], self.node[2 * k + 1]);
        // SAFETY of indexing: every stored value is ≤ n and times has n + 1 entries.
        if times[r as usize] < times[l as usize] {
            r
        } else {
            l
        }
    }

    /// The disk with the earliest event.
    #[inline(always)]
    pub fn min(&self) -> usize {
        self.node[1] as usize
    }

    /// Disk `i`'s event time changed: replay its matches up to the root.
    #[inline]
    pub fn update(&mut self, times: &[f64], i: usize) {
        let mut k = (self.leaves + i) >> 1;
        while k >= 1 {
            self.node[k] = self.winner(times, k);
            k >>= 1;
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.node.capacity() * 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    #[test]
    fn always_yields_the_minimum() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        for n in [1usize, 2, 3, 5, 17, 100] {
            let mut times: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
            times.push(f64::INFINITY);
            let mut tree = CompleteBinaryTree::build(&times);
            for _ in 0..500 {
                let argmin = (0..n)
                    .min_by(|&a, &b| times[a].partial_cmp(&times[b]).unwrap())
                    .unwrap();
                assert_eq!(times[tree.min()], times[argmin]);
                let i = rng.random_range(0..n);
                times[i] = if rng.random::<f64>() < 0.1 {
                    f64::INFINITY
                } else {
                    rng.random::<f64>()
                };
                tree.update(&times, i);
            }
        }
    }
}
