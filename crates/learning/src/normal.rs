//! Standard normal samples with the same bits on every machine.

use rand::Rng;
use rand::distr::{Distribution, StandardUniform};

/// The standard normal distribution `N(0, 1)` by Marsaglia's polar method: draw `(u, v)`
/// uniformly in the square `[−1, 1)²` until `0 < s = u² + v² < 1`, then `u·√(−2 ln s / s)` is
/// standard normal. Its logarithm comes from the `libm` crate, so a seed gives the same
/// samples on every machine (`rand_distr`'s ziggurat takes its tail from the platform's C
/// library, whose last bits differ between machines). Each sample uses one accepted pair
/// (`v`'s normal is not kept), so the distribution carries no state.
#[derive(Clone, Copy, Debug, Default)]
pub struct StandardNormal;

impl Distribution<f64> for StandardNormal {
    fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> f64 {
        loop {
            let (u, v): (f64, f64) = (StandardUniform.sample(rng), StandardUniform.sample(rng));
            let (u, v) = (2.0 * u - 1.0, 2.0 * v - 1.0);
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                return u * (-2.0 * libm::log(s) / s).sqrt();
            }
        }
    }
}

impl Distribution<f32> for StandardNormal {
    fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> f32 {
        Distribution::<f64>::sample(self, rng) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn samples_have_the_moments_and_tails_of_the_standard_normal() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let count = 400_000;
        let samples: Vec<f64> = (0..count).map(|_| rng.sample(StandardNormal)).collect();
        let n = count as f64;
        let mean = samples.iter().sum::<f64>() / n;
        let variance = samples.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n;
        let fourth = samples.iter().map(|x| x.powi(4)).sum::<f64>() / n;
        // Standard errors: 1/√n ≈ 0.0016 for the mean, √(2/n) ≈ 0.0022 for the variance.
        assert!(mean.abs() < 0.008, "mean {mean}");
        assert!((variance - 1.0).abs() < 0.011, "variance {variance}");
        assert!((fourth - 3.0).abs() < 0.06, "fourth moment {fourth}");
        // P(|x| > 2) = 0.0455, P(|x| > 3) = 0.0027 (binomial standard errors 0.0003, 0.00008).
        let beyond = |k: f64| samples.iter().filter(|x| x.abs() > k).count() as f64 / n;
        assert!((beyond(2.0) - 0.0455).abs() < 0.0015, "{}", beyond(2.0));
        assert!((beyond(3.0) - 0.0027).abs() < 0.0004, "{}", beyond(3.0));
    }

    #[test]
    fn a_seed_gives_the_same_samples() {
        let draw = || {
            let mut rng = ChaCha8Rng::seed_from_u64(11);
            (0..16)
                .map(|_| rng.sample(StandardNormal))
                .collect::<Vec<f32>>()
        };
        assert_eq!(draw(), draw());
    }
}
