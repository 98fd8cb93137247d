//! The figures of a campaign: the Wilson score interval of a success rate, and the
//! distribution of a quantity over runs (quantiles by nearest rank, a histogram).

use serde::{Deserialize, Serialize};

/// The two-sided 95 % normal quantile.
const Z95: f64 = 1.959_963_984_540_054;

/// The 95 % Wilson score interval of `successes` out of `n` trials (Wilson, "Probable
/// inference, the law of succession, and statistical inference", JASA 22, 1927; as in
/// Brown, Cai and DasGupta, "Interval Estimation for a Binomial Proportion", Statistical
/// Science 16, 2001, who recommend it over the Wald interval). With no trials, `[0, 1]`.
pub fn wilson(successes: u64, n: u64) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let successes = successes.min(n);
    let (n, p) = (n as f64, successes as f64 / n as f64);
    let z2 = Z95 * Z95;
    let centre = (p + z2 / (2.0 * n)) / (1.0 + z2 / n);
    let half = Z95 / (1.0 + z2 / n) * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    // At the ends the interval reaches 0 or 1 exactly: rounding must not leave it short
    // of the point estimate.
    let low = if successes == 0 { 0.0 } else { (centre - half).clamp(0.0, p) };
    let high = if successes as f64 == n { 1.0 } else { (centre + half).clamp(p, 1.0) };
    [low, high]
}

/// How a quantity spread over the runs: its least, median, 95th percentile and greatest
/// (each a value some run had: the nearest rank), and a histogram.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Distribution {
    pub min: f64,
    pub median: f64,
    pub p95: f64,
    pub max: f64,
    pub histogram: Vec<Bin>,
}

/// Runs whose value lies in `[from, to)` (the last bin holds `to` too).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bin {
    pub from: f64,
    pub to: f64,
    pub runs: u64,
}

/// How many bins a histogram has at most.
pub const BINS: usize = 20;

impl Distribution {
    /// The distribution of `values` (any order; values that are not finite are left out),
    /// or `None` when none is left. `whole`: the quantity is a count, so each bin spans
    /// whole numbers.
    pub fn of(values: &[f64], whole: bool) -> Option<Distribution> {
        let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        if sorted.is_empty() {
            return None;
        }
        sorted.sort_by(f64::total_cmp);
        let rank = |q: f64| {
            // Nearest rank: the smallest value with at least q of the values at or below.
            let k = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
            sorted[k - 1]
        };
        let (min, max) = (sorted[0], sorted[sorted.len() - 1]);
        Some(Distribution {
            min,
            median: rank(0.5),
            p95: rank(0.95),
            max,
            histogram: histogram(&sorted, min, max, whole),
        })
    }
}

/// `sorted` in at most [`BINS`] bins of equal width from `min` to `max`.
fn histogram(sorted: &[f64], min: f64, max: f64, whole: bool) -> Vec<Bin> {
    let (bins, width) = if whole {
        let span = (max - min) as u64 + 1;
        let width = span.div_ceil(BINS as u64).max(1);
        (span.div_ceil(width) as usize, width as f64)
    } else if max > min {
        (BINS, (max - min) / BINS as f64)
    } else {
        (1, 0.0)
    };
    let mut out: Vec<Bin> = (0..bins)
        .map(|i| {
            let from = min + i as f64 * width;
            let to = if whole {
                from + width - 1.0
            } else if i + 1 == bins {
                max
            } else {
                from + width
            };
            Bin { from, to, runs: 0 }
        })
        .collect();
    for v in sorted {
        let i = if width > 0.0 { ((v - min) / width).floor() as usize } else { 0 };
        if let Some(bin) = out.get_mut(i.min(bins - 1)) {
            bin.runs += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn the_interval_of_known_cases() {
        // Brown, Cai and DasGupta's table: 0 of 10 gives [0, 0.278].
        let [low, high] = wilson(0, 10);
        assert_eq!(low, 0.0);
        assert!((high - 0.2775).abs() < 1e-3, "{high}");
        let [low, high] = wilson(10, 10);
        assert!((low - 0.7225).abs() < 1e-3 && high == 1.0, "{low}");
        // 50 of 100: 0.404 to 0.596.
        let [low, high] = wilson(50, 100);
        assert!((low - 0.4038).abs() < 1e-3 && (high - 0.5962).abs() < 1e-3, "{low} {high}");
        assert_eq!(wilson(0, 0), [0.0, 1.0]);
    }

    proptest! {
        #[test]
        fn the_interval_holds_the_estimate_within_0_and_1(n in 1u64..1_000_000, k in 0u64..1_000_000) {
            let k = k % (n + 1);
            let p = k as f64 / n as f64;
            let [low, high] = wilson(k, n);
            prop_assert!((0.0..=1.0).contains(&low) && (0.0..=1.0).contains(&high));
            prop_assert!(low <= p && p <= high, "{low} <= {p} <= {high}");
        }

        #[test]
        fn more_runs_narrow_the_interval(k in 0u64..1000, n in 1u64..1000) {
            let k = k % (n + 1);
            let [a, b] = wilson(k, n);
            let [c, d] = wilson(k * 10, n * 10);
            prop_assert!(d - c <= b - a + 1e-12);
        }

        #[test]
        fn a_histogram_counts_every_value_and_the_quantiles_are_in_order(
            values in proptest::collection::vec(-1e6f64..1e6, 1..200), whole in any::<bool>()
        ) {
            let values: Vec<f64> = if whole { values.iter().map(|v| v.round()).collect() } else { values };
            let d = Distribution::of(&values, whole).unwrap();
            prop_assert_eq!(d.histogram.iter().map(|b| b.runs).sum::<u64>(), values.len() as u64);
            prop_assert!(d.min <= d.median && d.median <= d.p95 && d.p95 <= d.max);
            prop_assert!(d.histogram.len() <= BINS);
        }
    }
}
