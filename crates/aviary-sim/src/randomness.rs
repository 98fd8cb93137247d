//! The simulator's randomness: only where the world asks for it (a sensor's
//! `probability` below 1, a fault whose `at` is a range, the parts of `[air]`), and all of it drawn from the
//! run's seed, so that the same world, calls and seed give the same run.
//!
//! Each thing that draws has a stream of its own: a drone's detections (in the order the
//! drone meets the targets), each fault's time, and, with `[air]`, a drone's gusts, its
//! GPS error, its battery's capacity and each kind of its random faults. A stream is ChaCha8 (`rand_chacha`),
//! with the key the seed's 8 bytes, little-endian, then 24 zero bytes, and the stream
//! number `purpose << 56 | index` (a drone's or fault's index in the world file). Nothing
//! one stream draws moves another, so the draws depend on neither the order drones are
//! stepped in nor on the draws of other drones, and ChaCha's output for a key and a stream
//! is fixed by the algorithm, whatever the version of the crate or the machine. A number
//! drawn is the top 53 bits of the stream's next 64 (low word first), over 2^53: uniform
//! in [0, 1).

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

/// What a stream is drawn for: the top byte of its number.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Purpose {
    /// Drone `index`'s detections.
    Detection = 1,
    /// The time of fault `index` (of the world's `[[faults]]`, in file order).
    FaultTime = 2,
    /// Drone `index`'s turbulence (`[air.wind] turbulence`).
    Gusts = 3,
    /// Drone `index`'s GPS error (`[air.gps]`).
    Gps = 4,
    /// Drone `index`'s battery capacity (`[air.battery]`).
    Capacity = 5,
    /// The random faults of one kind on one drone (`[air.faults]`): index
    /// `drone * 8 + the kind's place in FaultKind::ALL`.
    RandomFault = 6,
}

/// One stream of numbers.
#[derive(Clone, Debug)]
pub(crate) struct Stream(ChaCha8Rng);

impl Stream {
    pub fn new(seed: u64, purpose: Purpose, index: usize) -> Stream {
        let mut key = [0u8; 32];
        key[..8].copy_from_slice(&seed.to_le_bytes());
        let mut rng = ChaCha8Rng::from_seed(key);
        rng.set_stream((purpose as u64) << 56 | (index as u64 & ((1 << 56) - 1)));
        Stream(rng)
    }

    /// A number drawn uniformly from [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A number drawn from the standard normal distribution: the first of
    /// [`Stream::normals`] (the second is not kept).
    pub fn normal(&mut self) -> f64 {
        self.normals()[0]
    }

    /// Two independent numbers of the standard normal distribution, from two uniform ones
    /// (Box-Muller).
    pub fn normals(&mut self) -> [f64; 2] {
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * (1.0 - u1).ln()).sqrt();
        let (sin, cos) = (std::f64::consts::TAU * u2).sin_cos();
        [r * cos, r * sin]
    }

    /// A waiting time drawn from the exponential distribution of mean `1 / rate`
    /// (infinite for a rate of 0).
    pub fn exponential(&mut self, rate: f64) -> f64 {
        -(1.0 - self.uniform()).ln() / rate
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The numbers of a seed do not change from one version to the next: a trace that a
    /// seed gave is the trace it gives.
    #[test]
    fn the_streams_are_fixed() {
        let first = |seed, purpose, index| Stream::new(seed, purpose, index).uniform();
        let pinned = [
            first(0, Purpose::Detection, 0),
            first(0, Purpose::Detection, 1),
            first(1, Purpose::Detection, 0),
            first(0, Purpose::FaultTime, 0),
        ];
        assert_eq!(
            pinned,
            [0.2564602688623301, 0.40111649128647275, 0.7186812048897427, 0.2898587291835939]
        );
    }

    #[test]
    fn normals_have_mean_zero_and_spread_one() {
        let mut s = Stream::new(7, Purpose::Gps, 3);
        let draws: Vec<f64> = (0..10_000).flat_map(|_| s.normals()).collect();
        let mean = draws.iter().sum::<f64>() / draws.len() as f64;
        let var = draws.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / draws.len() as f64;
        assert!(mean.abs() < 0.03, "{mean}");
        assert!((var - 1.0).abs() < 0.04, "{var}");
        let within = draws.iter().filter(|x| x.abs() < 1.0).count() as f64 / draws.len() as f64;
        assert!((within - 0.6827).abs() < 0.015, "{within}");
    }

    #[test]
    fn exponential_waits_have_mean_one_over_rate() {
        let mut s = Stream::new(7, Purpose::RandomFault, 9);
        let draws: Vec<f64> = (0..20_000).map(|_| s.exponential(0.5)).collect();
        let mean = draws.iter().sum::<f64>() / draws.len() as f64;
        assert!((mean - 2.0).abs() < 0.06, "{mean}");
        assert!(draws.iter().all(|&t| t >= 0.0));
        assert!(Stream::new(1, Purpose::RandomFault, 0).exponential(0.0).is_infinite());
    }

    #[test]
    fn numbers_are_uniform_in_zero_to_one() {
        let mut s = Stream::new(42, Purpose::Detection, 7);
        let draws: Vec<f64> = (0..10_000).map(|_| s.uniform()).collect();
        assert!(draws.iter().all(|u| (0.0..1.0).contains(u)));
        let mean = draws.iter().sum::<f64>() / draws.len() as f64;
        assert!((mean - 0.5).abs() < 0.02, "{mean}");
        let below = draws.iter().filter(|&&u| u < 0.25).count();
        assert!((2300..2700).contains(&below), "{below}");
    }
}
