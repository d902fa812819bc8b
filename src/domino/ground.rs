//! The ground model under a row: the paper's Coulomb friction, or a pivot
//! that never slips (the assumption of the cooperative model).

use serde::{Deserialize, Serialize};

/// How the ground holds a block's feet.
///
/// * [`Ground::Coulomb`] is the paper's model: the ground contact has Coulomb
///   friction μ2 in the smooth phase and μ2 × `impact_friction_factor`
///   inside impacts, so a struck block's foot may slip.
/// * [`Ground::NoSlip`] is the assumption of the cooperative model (Stronge &
///   Shu 1988; van Leeuwen 2004): a foot on the ground never slides, in the
///   smooth phase and inside impacts (tangential impulses unbounded); it may
///   still lift off.
///
/// Scene files and the CLI spell them `"coulomb"` and `"no-slip"`.
///
/// ```
/// use topple::domino::Ground;
/// assert_eq!(Ground::default(), Ground::Coulomb);
/// assert_eq!("no-slip".parse::<Ground>().unwrap(), Ground::NoSlip);
/// assert!("sticky".parse::<Ground>().is_err());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ground {
    /// Coulomb friction μ2 (the paper's model).
    #[default]
    Coulomb,
    /// The pivot never slips.
    NoSlip,
}

impl Ground {
    /// The spelling used by scene files and the CLI.
    pub fn name(self) -> &'static str {
        match self {
            Ground::Coulomb => "coulomb",
            Ground::NoSlip => "no-slip",
        }
    }
}

impl std::fmt::Display for Ground {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Ground {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "coulomb" => Ok(Ground::Coulomb),
            "no-slip" => Ok(Ground::NoSlip),
            other => Err(format!(
                "ground must be \"coulomb\" or \"no-slip\" (got \"{other}\")"
            )),
        }
    }
}
