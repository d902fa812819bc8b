//! Impact materials per collider and per pair (engine-agnostic).
//!
//! Each managed collider carries a [`MaterialId`]. A pair of materials takes
//! its [`PairMaterial`] from an explicit pair rule when one is set (as Table 1
//! of the paper distinguishes domino–domino from domino–ground), else from a
//! combination of the two materials (see [`MaterialTable::pair`]).

use crate::impact::ContactMaterial;

/// Index of a material in a [`MaterialTable`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialId(pub u16);

/// What a pair of colliders uses: the impact law for the LZB resolver and the
/// sliding friction of the smooth phase (handed to Rapier's solver).
///
/// The paper uses half the tabulated sliding friction inside impacts (Table 1,
/// footnote); [`PairMaterial::from_table`] applies that factor.
///
/// ```
/// use topple::impact::ContactMaterial;
/// use topple::coupling::PairMaterial;
/// let m = PairMaterial::from_table(ContactMaterial::hertz(2.3e8), 0.17, 0.20, 0.85, 0.5);
/// assert_eq!(m.impact.friction, 0.085);
/// assert_eq!(m.smooth_friction, 0.17);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairMaterial {
    /// Contact law used at impacts (stiffness k in N/m^α, α, e, μ, μ_s).
    pub impact: ContactMaterial,
    /// Coulomb friction of the smooth phase (Rapier's contact friction).
    pub smooth_friction: f64,
}

impl PairMaterial {
    /// A material from a table row: sliding friction μ, sticking friction μ_s,
    /// restitution e, and the factor applied to μ inside impacts (0.5 in the
    /// paper). `base` provides stiffness and exponent.
    pub fn from_table(
        base: ContactMaterial,
        friction: f64,
        stick_friction: f64,
        restitution: f64,
        impact_friction_factor: f64,
    ) -> Self {
        PairMaterial {
            impact: ContactMaterial {
                friction: friction * impact_friction_factor,
                stick_friction,
                restitution,
                ..base
            },
            smooth_friction: friction,
        }
    }

    /// Combination used when no pair rule is set: stiffnesses in series for the
    /// mean exponent ᾱ, k = (k₁^(−1/ᾱ) + k₂^(−1/ᾱ))^(−ᾱ) (two power-law springs
    /// carrying the same force); restitution, friction coefficients averaged.
    pub fn combine(a: &PairMaterial, b: &PairMaterial) -> PairMaterial {
        let alpha = 0.5 * (a.impact.exponent + b.impact.exponent);
        let ka = a.impact.stiffness.powf(-1.0 / alpha);
        let kb = b.impact.stiffness.powf(-1.0 / alpha);
        PairMaterial {
            impact: ContactMaterial {
                stiffness: (ka + kb).powf(-alpha),
                exponent: alpha,
                restitution: 0.5 * (a.impact.restitution + b.impact.restitution),
                friction: 0.5 * (a.impact.friction + b.impact.friction),
                stick_friction: 0.5 * (a.impact.stick_friction + b.impact.stick_friction),
            },
            smooth_friction: 0.5 * (a.smooth_friction + b.smooth_friction),
        }
    }
}

/// Materials and pair rules, with a dense pair table rebuilt on change so that
/// looking a pair up costs one index.
///
/// ```
/// use topple::impact::ContactMaterial;
/// use topple::coupling::{MaterialTable, PairMaterial};
/// let mut table = MaterialTable::default();
/// let block = table.add(PairMaterial { impact: ContactMaterial::hertz(2.3e8), smooth_friction: 0.0 });
/// let ground = table.add(PairMaterial { impact: ContactMaterial::hertz(6.9e8), smooth_friction: 0.9 });
/// let rule = PairMaterial { impact: ContactMaterial::hertz(6.9e8).with_restitution(0.0), smooth_friction: 0.9 };
/// table.set_pair(block, ground, rule);
/// assert_eq!(table.pair(ground, block), &rule);
/// assert_eq!(table.pair(block, block), table.material(block));
/// ```
#[derive(Clone, Debug, Default)]
pub struct MaterialTable {
    materials: Vec<PairMaterial>,
    rules: Vec<(MaterialId, MaterialId, PairMaterial)>,
    dense: Vec<PairMaterial>,
}

impl MaterialTable {
    /// Adds a material and returns its id.
    pub fn add(&mut self, material: PairMaterial) -> MaterialId {
        assert!(
            self.materials.len() < u16::MAX as usize,
            "too many materials"
        );
        self.materials.push(material);
        self.rebuild();
        MaterialId((self.materials.len() - 1) as u16)
    }

    /// Sets the material used between `a` and `b` (in either order).
    pub fn set_pair(&mut self, a: MaterialId, b: MaterialId, material: PairMaterial) {
        self.rules
            .retain(|(x, y, _)| !((*x, *y) == (a, b) || (*x, *y) == (b, a)));
        self.rules.push((a, b, material));
        self.rebuild();
    }

    /// Number of materials.
    pub fn len(&self) -> usize {
        self.materials.len()
    }

    /// True when no material was added.
    pub fn is_empty(&self) -> bool {
        self.materials.is_empty()
    }

    /// The material of one collider material id.
    pub fn material(&self, id: MaterialId) -> &PairMaterial {
        &self.materials[id.0 as usize]
    }

    /// The material of a pair: the pair rule if one is set, else
    /// [`PairMaterial::combine`].
    #[inline]
    pub fn pair(&self, a: MaterialId, b: MaterialId) -> &PairMaterial {
        &self.dense[a.0 as usize * self.materials.len() + b.0 as usize]
    }

    fn rebuild(&mut self) {
        let n = self.materials.len();
        self.dense.clear();
        for i in 0..n {
            for j in 0..n {
                let rule = self.rules.iter().find(|(x, y, _)| {
                    (x.0 as usize, y.0 as usize) == (i, j) || (x.0 as usize, y.0 as usize) == (j, i)
                });
                let m = match rule {
                    Some((_, _, m)) => *m,
                    None if i == j => self.materials[i],
                    None => PairMaterial::combine(&self.materials[i], &self.materials[j]),
                };
                self.dense.push(m);
            }
        }
    }
}
