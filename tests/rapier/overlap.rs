//! The deepest overlap of a column of colliders, measured with parry's own
//! contact query (independent of topple's pass and of Rapier's solver).

use topple::rapier2d_f64::parry::query;
use topple::rapier2d_f64::prelude::*;

/// The deepest overlap (m) between consecutive colliders of `column` (the
/// ground first, then each box on the one below), 0 where none overlap.
pub fn deepest_in_column(set: &ColliderSet, column: &[ColliderHandle]) -> f64 {
    let mut deepest: f64 = 0.0;
    for pair in column.windows(2) {
        let (a, b) = (&set[pair[0]], &set[pair[1]]);
        let c = query::contact(a.position(), a.shape(), b.position(), b.shape(), 0.0)
            .expect("boxes and the ground have a contact query");
        if let Some(c) = c {
            deepest = deepest.max(-c.dist);
        }
    }
    deepest
}
