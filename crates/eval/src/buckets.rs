//! Difficulty buckets by reference length (Sec. 5.1) and the length / ratio-to-reference
//! statistics of every table cell.

use crate::batch::Summary;
use serde::{Deserialize, Serialize};

/// Difficulty buckets by reference length `ℓ_ref` (Sec. 5.1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BucketConfig {
    /// `ℓ_ref` at or above which a task is Easy (m).
    pub easy_min_m: f64,
    /// `ℓ_ref` below which a task is Difficult (m); Medium lies between.
    pub difficult_below_m: f64,
}

impl Default for BucketConfig {
    fn default() -> Self {
        Self {
            easy_min_m: 0.80,
            difficult_below_m: 0.45,
        }
    }
}

/// A task's difficulty.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Difficulty {
    /// `ℓ_ref ≥ easy_min_m`.
    Easy,
    /// Between the two thresholds.
    Medium,
    /// `ℓ_ref < difficult_below_m`.
    Difficult,
}

impl Difficulty {
    /// All buckets in table order.
    pub const ALL: [Difficulty; 3] = [Self::Easy, Self::Medium, Self::Difficult];

    /// Capitalised name for tables.
    pub fn name(self) -> &'static str {
        match self {
            Self::Easy => "Easy",
            Self::Medium => "Medium",
            Self::Difficult => "Difficult",
        }
    }
}

impl BucketConfig {
    /// The bucket of a task with reference length `reference_m`.
    pub fn classify(&self, reference_m: f64) -> Difficulty {
        if reference_m >= self.easy_min_m {
            Difficulty::Easy
        } else if reference_m >= self.difficult_below_m {
            Difficulty::Medium
        } else {
            Difficulty::Difficult
        }
    }
}

/// Path length and ratio-to-reference statistics of one table cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellStats {
    /// Path length (m).
    pub length_m: Summary,
    /// `100 · L / ℓ_ref` (%), over the tasks with `ℓ_ref ≥` [`MIN_REFERENCE_M`].
    pub ratio_percent: Summary,
}

/// Shortest reference length (m) a ratio is taken against: the 1 cm grid of the reachability
/// bound. A shorter `ℓ_ref` comes from a task whose labelled starts hold the constraints but
/// hardly move (under the work surface, often none holds them and `ℓ_ref = 0`); a ratio to it
/// says nothing.
pub const MIN_REFERENCE_M: f64 = 0.01;

/// Statistics of `lengths` over the tasks `members` (indices into `lengths` and `references`);
/// the ratios over those with `ℓ_ref ≥` [`MIN_REFERENCE_M`] only. `None` when no member has
/// such a reference.
pub fn cell_stats(lengths: &[f64], references: &[f64], members: &[usize]) -> Option<CellStats> {
    let picked: Vec<f64> = members.iter().map(|&i| lengths[i]).collect();
    let ratios: Vec<f64> = members
        .iter()
        .filter(|&&i| references[i] >= MIN_REFERENCE_M)
        .map(|&i| 100.0 * lengths[i] / references[i])
        .collect();
    Some(CellStats {
        length_m: Summary::of(&picked)?,
        ratio_percent: Summary::of(&ratios)?,
    })
}

/// Task indices grouped by bucket, in task order.
pub fn bucket_members(references: &[f64], config: &BucketConfig) -> Vec<(Difficulty, Vec<usize>)> {
    Difficulty::ALL
        .iter()
        .map(|&bucket| {
            let members = (0..references.len())
                .filter(|&i| config.classify(references[i]) == bucket)
                .collect();
            (bucket, members)
        })
        .collect()
}
