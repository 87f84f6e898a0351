//! The sinusoidal time embedding shared by the Burn model and the plain forward.

/// Writes the sinusoidal embedding of timestep `t` into `out` (length `time_dim`, even):
/// `out[i] = sin(t·ω_i)`, `out[half + i] = cos(t·ω_i)`, `ω_i = 10000^(−i/half)`.
pub fn sinusoidal_embedding(t: usize, out: &mut [f32]) {
    let half = out.len() / 2;
    let (sines, cosines) = out.split_at_mut(half);
    for (i, (s, c)) in sines.iter_mut().zip(cosines.iter_mut()).enumerate() {
        let frequency = libm::exp(-libm::log(10_000.0) * i as f64 / half as f64);
        let (sin, cos) = libm::sincos(t as f64 * frequency);
        *s = sin as f32;
        *c = cos as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedding_of_zero_is_sines_zero_cosines_one() {
        let mut out = [9.0f32; 8];
        sinusoidal_embedding(0, &mut out);
        assert_eq!(out, [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]);
        sinusoidal_embedding(3, &mut out);
        assert!((out[0] - libm::sinf(3.0)).abs() < 1e-6 && (out[4] - libm::cosf(3.0)).abs() < 1e-6);
    }
}
