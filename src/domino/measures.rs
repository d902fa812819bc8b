//! The wave-speed measures of the paper (Sec. 3.1, Eq. 33); their definitions are in docs/model.md, "Measures of the wave".

use serde::{Deserialize, Serialize};

use super::RowSpec;

/// The natural speed is averaged over the blocks after this one (1-based): the
/// paper lets the wave pass "the first 6 blocks" (Sec. 3.1).
pub const FIRST_STEADY_BLOCK: usize = 7;

/// JSON has no infinity or NaN: serde_json writes them as `null`. These read
/// `null` back as NaN, so that a saved report with a non-finite value (two
/// blocks hit in the same Rapier step give t_i = 0 and v̂_i = ∞) still loads.
pub(crate) mod nullable {
    use serde::{Deserialize, Deserializer};

    /// One number, `null` → NaN.
    pub fn number<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }

    /// A list of numbers, each `null` → NaN.
    pub fn numbers<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        let v = Vec::<Option<f64>>::deserialize(d)?;
        Ok(v.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect())
    }
}

/// Mean, standard deviation, minimum and maximum of a sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    /// Arithmetic mean.
    #[serde(deserialize_with = "nullable::number")]
    pub mean: f64,
    /// Sample standard deviation (0 for one value).
    #[serde(deserialize_with = "nullable::number")]
    pub std_dev: f64,
    /// Smallest value.
    #[serde(deserialize_with = "nullable::number")]
    pub min: f64,
    /// Largest value.
    #[serde(deserialize_with = "nullable::number")]
    pub max: f64,
    /// Number of values.
    pub count: usize,
}

impl Spread {
    /// The spread of `values`, or `None` if there are none.
    pub fn of(values: &[f64]) -> Option<Spread> {
        if values.is_empty() {
            return None;
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = if values.len() > 1 {
            values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)
        } else {
            0.0
        };
        Some(Spread {
            mean,
            std_dev: var.sqrt(),
            min: values.iter().cloned().fold(f64::INFINITY, f64::min),
            max: values.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
            count: values.len(),
        })
    }
}

/// Wave measures from hit times.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WaveMeasures {
    /// t_i (s): from block i being hit to block i hitting block i+1, for
    /// i = 1..k−1 when blocks 1..k were hit.
    pub intervals: Vec<f64>,
    /// v̂_i = (s + d)/(t_i √(g h)) (Eq. 33), same indexing as `intervals`.
    pub speeds: Vec<f64>,
    /// v̂_na: the spread of v̂_i over i ≥ [`FIRST_STEADY_BLOCK`]; `None` when the
    /// wave did not get that far.
    pub natural_speed: Option<Spread>,
}

impl WaveMeasures {
    /// Measures from the hit times (s) of blocks 1, 2, … (block 1 at t = 0),
    /// a contiguous prefix of the row (the wave stops at the first block it does
    /// not reach).
    pub fn from_hit_times(row: &RowSpec, hit_times: &[f64]) -> WaveMeasures {
        let vbar = row.params.speed_scale();
        let intervals: Vec<f64> = hit_times.windows(2).map(|w| w[1] - w[0]).collect();
        let speeds: Vec<f64> = intervals.iter().map(|t| row.pitch() / (t * vbar)).collect();
        let steady = speeds.get(FIRST_STEADY_BLOCK - 1..).unwrap_or(&[]);
        WaveMeasures {
            natural_speed: Spread::of(steady),
            intervals,
            speeds,
        }
    }
}
