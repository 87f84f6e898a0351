//! The path-speed profile in time: the TOPP-RA profile (`s̈` constant between grid points) and
//! its jerk-limited form, a moving average of `s(t)` over a window `w` (then `s̈` is continuous
//! and `s⃛ = (s̈(t) − s̈(t − w)) / w` is bounded), which also starts and ends the motion with
//! zero path speed and acceleration.

/// The path position and its first two time derivatives at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathState {
    /// `s` (path parameter).
    pub s: f64,
    /// `ṡ`.
    pub sd: f64,
    /// `s̈`.
    pub sdd: f64,
}

/// One stretch of constant `s̈` between two grid points.
#[derive(Clone, Copy, Debug)]
struct Piece {
    /// Start time.
    t0: f64,
    /// Path position at the start.
    s0: f64,
    /// Path speed at the start.
    v0: f64,
    /// Path acceleration.
    u: f64,
    /// `∫₀^{t0} s dt`.
    integral0: f64,
}

/// The TOPP-RA profile as a function of time, from rest at `s = 0` to rest at the path's end.
#[derive(Clone, Debug)]
pub struct SpeedProfile {
    pieces: Vec<Piece>,
    duration: f64,
    end: f64,
    integral_end: f64,
}

impl SpeedProfile {
    /// The profile of path speeds `x_i = ṡ²` at the grid points `s_i` (`x_0 = x_N = 0`, every
    /// other `x_i > 0`): piece `i` lasts `2Δ_i / (√x_i + √x_{i+1})` at
    /// `s̈ = (x_{i+1} − x_i) / 2Δ_i`.
    pub fn new(s: &[f64], x: &[f64]) -> Self {
        let mut pieces = Vec::with_capacity(s.len() - 1);
        let (mut t, mut integral) = (0.0, 0.0);
        for (g, x) in s.windows(2).zip(x.windows(2)) {
            let delta = g[1] - g[0];
            let (v0, v1) = (x[0].sqrt(), x[1].sqrt());
            let u = (x[1] - x[0]) / (2.0 * delta);
            let tau = 2.0 * delta / (v0 + v1);
            pieces.push(Piece {
                t0: t,
                s0: g[0],
                v0,
                u,
                integral0: integral,
            });
            integral += g[0] * tau + v0 * tau * tau / 2.0 + u * tau * tau * tau / 6.0;
            t += tau;
        }
        Self {
            pieces,
            duration: t,
            end: s[s.len() - 1],
            integral_end: integral,
        }
    }

    /// Time from rest to rest (s).
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// `(∫₀ᵗ s, s, ṡ)` at `t`, with rest at 0 before the start and at the end after it,
    /// searching forward from piece `*hint` (which it updates): times that increase from call
    /// to call cost O(1) each.
    fn at_from(&self, t: f64, hint: &mut usize) -> [f64; 3] {
        if t <= 0.0 {
            return [0.0; 3];
        }
        if t >= self.duration {
            return [
                self.integral_end + self.end * (t - self.duration),
                self.end,
                0.0,
            ];
        }
        if *hint >= self.pieces.len() || self.pieces[*hint].t0 > t {
            *hint = self.pieces.partition_point(|p| p.t0 <= t) - 1;
        }
        while *hint + 1 < self.pieces.len() && self.pieces[*hint + 1].t0 <= t {
            *hint += 1;
        }
        let p = &self.pieces[*hint];
        let tau = t - p.t0;
        [
            p.integral0 + (p.s0 + (p.v0 / 2.0 + p.u * tau / 6.0) * tau) * tau,
            p.s0 + (p.v0 + p.u * tau / 2.0) * tau,
            p.v0 + p.u * tau,
        ]
    }
}

/// A [`SpeedProfile`] averaged over a moving window of `window` seconds: `s_w(t) = (1/w)
/// ∫_{t−w}^{t} s`. It lasts `w` longer, keeps `|ṡ|` and `|s̈|` within the largest values of the
/// window, and has `|s⃛| ≤ 2 max|s̈| / w`.
#[derive(Clone, Debug)]
pub struct SmoothedProfile {
    profile: SpeedProfile,
    window: f64,
}

impl SmoothedProfile {
    /// `profile` averaged over `window` (s, > 0).
    pub fn new(profile: SpeedProfile, window: f64) -> Self {
        assert!(window > 0.0, "a positive window");
        Self { profile, window }
    }

    /// Time from rest to rest (s).
    pub fn duration(&self) -> f64 {
        self.profile.duration + self.window
    }

    /// The averaging window (s).
    pub fn window(&self) -> f64 {
        self.window
    }

    /// `s` and its derivatives at `t`; exactly the path's end and at rest from the end of the
    /// motion on.
    pub fn state(&self, t: f64) -> PathState {
        self.state_from(t, &mut [0, 0])
    }

    /// As [`Self::state`], searching forward from the pieces `hints` (which it updates) for
    /// `t` and `t − w`: times that increase from call to call cost O(1) each.
    pub fn state_from(&self, t: f64, hints: &mut [usize; 2]) -> PathState {
        if t >= self.duration() {
            return PathState {
                s: self.profile.end,
                sd: 0.0,
                sdd: 0.0,
            };
        }
        let w = self.window;
        let [now_hint, before_hint] = hints;
        let now = self.profile.at_from(t, now_hint);
        let before = self.profile.at_from(t - w, before_hint);
        PathState {
            s: ((now[0] - before[0]) / w).clamp(0.0, self.profile.end),
            sd: (now[1] - before[1]) / w,
            sdd: (now[2] - before[2]) / w,
        }
    }
}
