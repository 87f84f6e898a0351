//! The cosine noise schedule `ᾱ_t` and the DDIM time grid.

use std::f64::consts::FRAC_PI_2;

/// Offset `s` of the cosine schedule (Nichol & Dhariwal; SPEC §6).
const COSINE_OFFSET: f64 = 0.008;

/// Largest per-step `β_t`, which keeps `ᾱ_{T−1}` away from exactly zero.
const MAX_BETA: f64 = 0.999;

/// Cumulative signal levels `ᾱ_t`, `t = 0 … T−1`, of the cosine schedule
/// `ᾱ(τ) = cos²((τ + s)/(1 + s) · π/2) / cos²(s/(1 + s) · π/2)`, discretised through
/// `β_t = min(1 − ᾱ((t+1)/T)/ᾱ(t/T), 0.999)` and `ᾱ_t = Π_{i≤t} (1 − β_i)`.
#[derive(Clone, Debug)]
pub struct CosineSchedule {
    alpha_bar: Vec<f64>,
}

impl CosineSchedule {
    /// The schedule of length `timesteps` (T).
    pub fn new(timesteps: usize) -> Self {
        let f = |tau: f64| {
            let cos = libm::cos((tau + COSINE_OFFSET) / (1.0 + COSINE_OFFSET) * FRAC_PI_2);
            cos * cos
        };
        let t_count = timesteps as f64;
        let mut product = 1.0;
        let alpha_bar = (0..timesteps)
            .map(|t| {
                let beta =
                    (1.0 - f((t + 1) as f64 / t_count) / f(t as f64 / t_count)).min(MAX_BETA);
                product *= 1.0 - beta;
                product
            })
            .collect();
        Self { alpha_bar }
    }

    /// `T`.
    pub fn len(&self) -> usize {
        self.alpha_bar.len()
    }

    /// Whether the schedule has no steps.
    pub fn is_empty(&self) -> bool {
        self.alpha_bar.is_empty()
    }

    /// `ᾱ_t`.
    pub fn alpha_bar(&self, t: usize) -> f64 {
        self.alpha_bar[t]
    }

    /// The DDIM evaluation times: `steps` indices from `T−1` down to `0`, evenly spaced and
    /// rounded (distinct for `1 ≤ steps ≤ T`); after the last one the sample is clean (`ᾱ = 1`).
    pub fn ddim_times(&self, steps: usize) -> Vec<usize> {
        (0..steps).map(|k| self.ddim_time(k, steps)).collect()
    }

    /// The `k`-th of the [`ddim_times`](Self::ddim_times), computed without allocating.
    pub fn ddim_time(&self, k: usize, steps: usize) -> usize {
        let last = self.len() - 1;
        if steps <= 1 {
            return last;
        }
        (last as f64 * (1.0 - k as f64 / (steps - 1) as f64)).round() as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alpha_bar_decreases_from_one_to_nearly_zero() {
        let schedule = CosineSchedule::new(1000);
        assert!(schedule.alpha_bar(0) > 0.9999 && schedule.alpha_bar(0) < 1.0);
        assert!(schedule.alpha_bar(999) < 1e-4 && schedule.alpha_bar(999) > 0.0);
        for t in 1..1000 {
            assert!(schedule.alpha_bar(t) < schedule.alpha_bar(t - 1), "t = {t}");
        }
    }

    #[test]
    fn ddim_times_are_distinct_and_span_the_schedule() {
        let schedule = CosineSchedule::new(1000);
        for steps in [1, 2, 10, 50, 999, 1000] {
            let times = schedule.ddim_times(steps);
            assert_eq!(times.len(), steps);
            assert_eq!(times[0], 999);
            assert!(times.windows(2).all(|w| w[0] > w[1]), "steps = {steps}");
            if steps > 1 {
                assert_eq!(*times.last().unwrap(), 0);
            }
        }
    }
}
