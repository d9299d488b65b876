//! What `gnomon calibrate` sweeps and how it picks: ranges of the bias settings
//! (`LOW..HIGH:STEPS`), the grid of their combinations, and the Pareto front of
//! false shadow against false lit.

use std::{fmt, str::FromStr};

/// An evenly spaced range of one setting: `STEPS` values from `LOW` to `HIGH`
/// inclusive (one value, `LOW`, when `STEPS` is 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepRange {
    pub low: f32,
    pub high: f32,
    pub steps: u32,
}

/// The most values one range may hold: the sweep renders every combination.
pub const MAX_STEPS: u32 = 64;

/// Why a range was refused; the caller adds which setting and where it came from.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RangeError {
    #[error("`{0}` is not LOW..HIGH:STEPS (for example 0..3:7)")]
    Syntax(String),
    #[error("`{0}` is not a finite number")]
    Number(String),
    #[error("{low}..{high} is inverted: LOW must not exceed HIGH")]
    Inverted { low: f32, high: f32 },
    #[error("{steps} steps: a range holds 1 to {MAX_STEPS} values")]
    Steps { steps: u32 },
    #[error("{low}..{high} holds more than one value in {steps} step: give STEPS ≥ 2, or LOW = HIGH")]
    Empty { low: f32, high: f32, steps: u32 },
}

impl SweepRange {
    /// The range's values, from low to high.
    pub fn values(&self) -> Vec<f32> {
        if self.steps == 1 {
            return vec![self.low];
        }
        let span = self.high - self.low;
        (0..self.steps).map(|i| self.low + span * i as f32 / (self.steps - 1) as f32).collect()
    }
}

impl FromStr for SweepRange {
    type Err = RangeError;

    fn from_str(s: &str) -> Result<Self, RangeError> {
        let (bounds, steps) = s.split_once(':').ok_or_else(|| RangeError::Syntax(s.into()))?;
        let (low, high) = bounds.split_once("..").ok_or_else(|| RangeError::Syntax(s.into()))?;
        let number = |t: &str| {
            t.trim()
                .parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| RangeError::Number(t.trim().into()))
        };
        let (low, high) = (number(low)?, number(high)?);
        let steps: u32 = steps.trim().parse().map_err(|_| RangeError::Syntax(s.into()))?;
        if low > high {
            return Err(RangeError::Inverted { low, high });
        }
        if !(1..=MAX_STEPS).contains(&steps) {
            return Err(RangeError::Steps { steps });
        }
        if steps == 1 && low != high {
            return Err(RangeError::Empty { low, high, steps });
        }
        Ok(Self { low, high, steps })
    }
}

impl fmt::Display for SweepRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}..{}:{}", self.low, self.high, self.steps)
    }
}

/// One point of the sweep and what it measured, pooled over the calibration views.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured<S> {
    pub setting: S,
    /// Wrongly shadowed light-facing pixels over all views / light-facing pixels.
    pub false_shadow: f64,
    /// Wrongly lit light-facing pixels over all views / light-facing pixels.
    pub false_lit: f64,
}

impl<S> Measured<S> {
    pub fn mismatch(&self) -> f64 {
        self.false_shadow + self.false_lit
    }

    /// Whether `self` is at least as good as `other` on both axes and better on one.
    fn dominates(&self, other: &Self) -> bool {
        self.false_shadow <= other.false_shadow
            && self.false_lit <= other.false_lit
            && (self.false_shadow < other.false_shadow || self.false_lit < other.false_lit)
    }
}

/// The indices of the points no other point dominates, in order of rising false
/// shadow (so falling false lit): the front a user chooses a trade-off along.
pub fn pareto_front<S>(points: &[Measured<S>]) -> Vec<usize> {
    let mut front: Vec<usize> =
        (0..points.len()).filter(|&i| !points.iter().any(|p| p.dominates(&points[i]))).collect();
    front.sort_by(|&a, &b| {
        points[a]
            .false_shadow
            .total_cmp(&points[b].false_shadow)
            .then(points[b].false_lit.total_cmp(&points[a].false_lit))
    });
    front.dedup_by(|a, b| {
        points[*a].false_shadow == points[*b].false_shadow && points[*a].false_lit == points[*b].false_lit
    });
    front
}

/// The index of the point with the least total mismatch (the first on ties): always
/// on the Pareto front.
pub fn least_mismatch<S>(points: &[Measured<S>]) -> Option<usize> {
    (0..points.len()).min_by(|&a, &b| points[a].mismatch().total_cmp(&points[b].mismatch()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_and_bad_ones_say_why() {
        let r: SweepRange = "0..3:4".parse().unwrap();
        assert_eq!(r.values(), [0.0, 1.0, 2.0, 3.0]);
        assert_eq!("1.5..1.5:1".parse::<SweepRange>().unwrap().values(), [1.5]);
        assert_eq!("2..1:3".parse::<SweepRange>(), Err(RangeError::Inverted { low: 2.0, high: 1.0 }));
        assert_eq!("0..1:0".parse::<SweepRange>(), Err(RangeError::Steps { steps: 0 }));
        assert_eq!("0..1:1".parse::<SweepRange>(), Err(RangeError::Empty { low: 0.0, high: 1.0, steps: 1 }));
        assert!(matches!("0..x:3".parse::<SweepRange>(), Err(RangeError::Number(_))));
        assert!(matches!("0..inf:3".parse::<SweepRange>(), Err(RangeError::Number(_))));
        assert!(matches!("0-3:3".parse::<SweepRange>(), Err(RangeError::Syntax(_))));
        assert!(matches!("0..3".parse::<SweepRange>(), Err(RangeError::Syntax(_))));
    }

    fn point(false_shadow: f64, false_lit: f64) -> Measured<()> {
        Measured { setting: (), false_shadow, false_lit }
    }

    #[test]
    fn the_front_keeps_exactly_the_undominated_points() {
        let points = [point(0.1, 0.5), point(0.2, 0.2), point(0.3, 0.3), point(0.5, 0.1), point(0.2, 0.4)];
        assert_eq!(pareto_front(&points), [0, 1, 3]);
        assert_eq!(least_mismatch(&points), Some(1));
        // Property: every point off the front is dominated by one on it, and the
        // least-mismatch point is on the front.
        let mut seed = 12345u32;
        let mut next = || {
            seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
            (seed >> 8) as f64 / (1u32 << 24) as f64
        };
        for _ in 0..50 {
            let points: Vec<_> = (0..30).map(|_| point(next(), next())).collect();
            let front = pareto_front(&points);
            for i in 0..points.len() {
                if !front.contains(&i) {
                    assert!(front.iter().any(|&f| points[f].dominates(&points[i])));
                }
            }
            assert!(front.contains(&least_mismatch(&points).unwrap()));
            assert!(front.windows(2).all(|w| points[w[0]].false_lit >= points[w[1]].false_lit));
        }
    }
}
