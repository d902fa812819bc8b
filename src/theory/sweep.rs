//! A sweep over the spacing s/h for several models, and its CSV table.

use super::{solve, Geometry, Model, Outcome, TheoryError};
use crate::par::prelude::*;
use std::io::Write;

/// One spacing of a sweep: the outcome of each model, in the order given.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepRow {
    /// s/h.
    pub spacing_ratio: f64,
    /// One outcome per model.
    pub outcomes: Vec<Outcome>,
}

/// Solves every model at every spacing (in parallel over spacings; each point
/// is independent, so the result does not depend on the thread count).
///
/// ```
/// use topple::theory::{sweep, Model};
/// let rows = sweep(&[Model::Cooperative, Model::Extended { mu: 0.15 }], 0.12, &[0.2, 0.4]).unwrap();
/// assert_eq!(rows.len(), 2);
/// assert!(rows[1].outcomes[0].natural_speed().unwrap() > rows[1].outcomes[1].natural_speed().unwrap());
/// ```
pub fn sweep(
    models: &[Model],
    thickness_ratio: f64,
    spacings: &[f64],
) -> Result<Vec<SweepRow>, TheoryError> {
    for m in models {
        m.validate()?;
    }
    spacings
        .par_iter()
        .map(|&s| {
            let geom = Geometry::new(thickness_ratio, s)?;
            let outcomes = models
                .iter()
                .map(|m| solve(m, &geom))
                .collect::<Result<Vec<_>, _>>()?;
            Ok(SweepRow {
                spacing_ratio: s,
                outcomes,
            })
        })
        .collect()
}

/// Writes the sweep as CSV: `s_over_h`, then for each model its natural speed
/// v/√(gh) (empty when there is no wave) and a `<model>_no_wave` column with the
/// reason. Column names carry μ and e, e.g. `extended_mu0.15`.
///
/// ```
/// use topple::theory::{sweep, write_csv, Model};
/// let models = [Model::Cooperative];
/// let rows = sweep(&models, 0.12, &[0.3, 1.5]).unwrap();
/// let mut out = Vec::new();
/// write_csv(&mut out, &models, &rows).unwrap();
/// let text = String::from_utf8(out).unwrap();
/// assert!(text.starts_with("s_over_h,cooperative,cooperative_no_wave\n0.3,"));
/// assert!(text.contains("\n1.5,,s >= h"));
/// ```
pub fn write_csv(mut out: impl Write, models: &[Model], rows: &[SweepRow]) -> std::io::Result<()> {
    let mut header = String::from("s_over_h");
    for m in models {
        let label = column_label(m);
        header.push_str(&format!(",{label},{label}_no_wave"));
    }
    writeln!(out, "{header}")?;
    for row in rows {
        let mut line = format!("{}", row.spacing_ratio);
        for o in &row.outcomes {
            match o {
                Outcome::Wave(w) => line.push_str(&format!(",{:.10},", w.natural_speed)),
                Outcome::NoWave(r) => {
                    line.push_str(&format!(",,{}", r.to_string().replace(',', ";")))
                }
            }
        }
        writeln!(out, "{line}")?;
    }
    Ok(())
}

/// Column label of a model: its name with its parameters.
pub(crate) fn column_label(m: &Model) -> String {
    match *m {
        Model::Cooperative => "cooperative".into(),
        Model::Extended { mu } => format!("extended_mu{mu}"),
        Model::Single { mu, e } => format!("single_mu{mu}_e{e}"),
    }
}
