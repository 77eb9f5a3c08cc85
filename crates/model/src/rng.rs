//! brtf's one seeded random number generator (the tracer's Monte Carlo,
//! synthetic measurement noise, test materials).
//!
//! Every pixel, gonio direction or sample gets its own stream, seeded
//! from `(seed, stream index)`, so results do not depend on how rayon
//! splits the work or on the number of threads. The generator is
//! SplitMix64 (Steele, Lea & Flood 2014): one 64-bit add and a
//! bijective mix per number, which is plenty for Monte Carlo integration.

/// The SplitMix64 increment (2⁶⁴/φ).
const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// The SplitMix64 finaliser: a bijective mix of 64 bits.
#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A deterministic stream of uniform numbers.
#[derive(Debug, Clone)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// The stream number `stream` of the run seeded with `seed`.
    pub fn new(seed: u64, stream: u64) -> Rng {
        Rng {
            state: mix(seed ^ mix(stream.wrapping_mul(GAMMA).wrapping_add(GAMMA))),
        }
    }

    /// The plain SplitMix64 sequence started at `state` (no stream mixing):
    /// for sequences that must stay as earlier brtf versions drew them.
    pub fn from_state(state: u64) -> Rng {
        Rng { state }
    }

    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GAMMA);
        mix(self.state)
    }

    /// Uniform in [0, 1), with 53 random bits.
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in (0, 1): the midpoints of the 2⁵³ cells, never 0, so
    /// its logarithm is finite.
    #[inline]
    pub fn uniform_open(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
    }

    /// A standard normal deviate (Box-Muller, one of the pair).
    pub fn normal(&mut self) -> f64 {
        let (a, b) = (self.uniform_open(), self.uniform_open());
        (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
    }

    /// Two uniform numbers in [0, 1).
    #[inline]
    pub fn uniform2(&mut self) -> [f64; 2] {
        [self.uniform(), self.uniform()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<u64> = (0..4).map(|_| Rng::new(1, 7).next_u64()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        assert_ne!(Rng::new(1, 7).next_u64(), Rng::new(1, 8).next_u64());
        assert_ne!(Rng::new(1, 7).next_u64(), Rng::new(2, 7).next_u64());
    }

    #[test]
    fn uniform_has_the_right_mean_and_range() {
        let mut rng = Rng::new(3, 0);
        let n = 100_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let u = rng.uniform();
            assert!((0.0..1.0).contains(&u));
            sum += u;
        }
        assert!((sum / n as f64 - 0.5).abs() < 0.005);
    }

    #[test]
    fn normal_has_unit_variance() {
        let mut rng = Rng::from_state(11);
        let n = 100_000;
        let (mut s1, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let z = rng.normal();
            s1 += z;
            s2 += z * z;
        }
        let mean = s1 / n as f64;
        assert!(mean.abs() < 0.01, "{mean}");
        assert!((s2 / n as f64 - 1.0).abs() < 0.02);
    }
}
