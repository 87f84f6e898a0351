//! Shares of a reference length by bucket of the task's reachability bound: how much of what
//! is reachable a planner reaches, where the line is short and where it is long.
//!
//! A share is length-weighted, `Σ L / Σ ℓ` over the bucket's tasks, beside the task mean of
//! `L / ℓ`: the task mean weighs a 0.3 m line like a 1.5 m one and so hides the long lines a
//! planner falls short on. Tasks are bucketed by their bound, never by what a planner reached,
//! since a long line a planner fails on would land in a short bucket.

use serde::{Deserialize, Serialize};

/// Upper edges of the bound buckets (m): `< 0.5`, `0.5 – 1`, `≥ 1`.
pub const BOUND_BUCKET_EDGES_M: [f64; 2] = [0.5, 1.0];

/// One bucket of tasks by their bound, and a planner's share of a reference over it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoundShare {
    /// The bucket: `< 0.5 m`, `0.5 – 1 m`, `≥ 1 m`, or `all`.
    pub bucket: String,
    /// Tasks in the bucket.
    pub tasks: usize,
    /// `Σ L / Σ ℓ` over the bucket's tasks (0 when `Σ ℓ` is 0).
    pub share: f64,
    /// Mean over the bucket's tasks of `L / ℓ`, where `ℓ` is positive.
    pub task_mean_share: f64,
    /// Tasks where `L < ℓ / 2`, by index.
    pub below_half: Vec<usize>,
}

/// The bucket name of a task whose bound is `bound_m`.
pub fn bound_bucket(bound_m: f64) -> &'static str {
    if bound_m < BOUND_BUCKET_EDGES_M[0] {
        "< 0.5 m"
    } else if bound_m < BOUND_BUCKET_EDGES_M[1] {
        "0.5 – 1 m"
    } else {
        "≥ 1 m"
    }
}

/// The share of `references` that `lengths` reach, per bucket of `bounds` (in increasing order
/// of the bound, empty buckets included) and then over all tasks. The three slices are indexed
/// by task.
pub fn bound_shares(lengths: &[f64], references: &[f64], bounds: &[f64]) -> Vec<BoundShare> {
    let buckets = ["< 0.5 m", "0.5 – 1 m", "≥ 1 m"];
    let all: Vec<usize> = (0..lengths.len()).collect();
    buckets
        .iter()
        .map(|&name| {
            let members: Vec<usize> = all
                .iter()
                .copied()
                .filter(|&i| bound_bucket(bounds[i]) == name)
                .collect();
            share_of(name, &members, lengths, references)
        })
        .chain(std::iter::once(share_of("all", &all, lengths, references)))
        .collect()
}

fn share_of(bucket: &str, members: &[usize], lengths: &[f64], references: &[f64]) -> BoundShare {
    let total = |values: &[f64]| members.iter().map(|&i| values[i]).sum::<f64>();
    let reference_sum = total(references);
    let ratios: Vec<f64> = members
        .iter()
        .filter(|&&i| references[i] > 0.0)
        .map(|&i| lengths[i] / references[i])
        .collect();
    BoundShare {
        bucket: bucket.to_string(),
        tasks: members.len(),
        share: if reference_sum > 0.0 {
            total(lengths) / reference_sum
        } else {
            0.0
        },
        task_mean_share: ratios.iter().sum::<f64>() / ratios.len().max(1) as f64,
        below_half: members
            .iter()
            .copied()
            .filter(|&i| lengths[i] < 0.5 * references[i])
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_are_length_weighted_and_bucketed_by_the_bound() {
        // A short line reached in full and a long one reached to a fifth: the task mean is
        // 0.6, the length-weighted share 0.5 / 1.5 = 1/3.
        let lengths = [0.3, 0.24];
        let references = [0.3, 1.2];
        let bounds = [0.3, 1.2];
        let shares = bound_shares(&lengths, &references, &bounds);
        let names: Vec<&str> = shares.iter().map(|s| s.bucket.as_str()).collect();
        assert_eq!(names, ["< 0.5 m", "0.5 – 1 m", "≥ 1 m", "all"]);
        assert_eq!(
            (shares[0].tasks, shares[1].tasks, shares[2].tasks),
            (1, 0, 1)
        );
        assert!((shares[0].share - 1.0).abs() < 1e-12);
        assert_eq!(shares[1].share, 0.0);
        assert!((shares[2].share - 0.2).abs() < 1e-12);
        assert!((shares[3].share - 0.54 / 1.5).abs() < 1e-12);
        assert!((shares[3].task_mean_share - 0.6).abs() < 1e-12);
        assert_eq!(shares[3].below_half, [1]);
        assert_eq!(bound_bucket(0.5), "0.5 – 1 m");
        assert_eq!(bound_bucket(1.0), "≥ 1 m");
    }
}
