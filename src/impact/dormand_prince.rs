//! The coefficients of the Dormand–Prince 5(4) pair (Dormand and Prince
//! 1980), with the continuous extension of order 4 given by Hairer, Nørsett
//! and Wanner (*Solving Ordinary Differential Equations I*, 2nd ed.,
//! Sec. II.6). One definition for the crate: the impact resolver's
//! time-domain solver (`impact/solver/tableau.rs`) and the reference
//! engine's adaptive smooth phase (`reference/stepper.rs`) both step with it.

/// Nodes c_i.
pub(crate) const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];

/// Coefficients a_ij (row i: its i coefficients, padded with zeros); the
/// last row holds the weights b of order 5, so the seventh stage is taken
/// at the new state (first same as last).
pub(crate) const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];

/// Weights b of order 5 (the last row of [`A`], the seventh stage's weight 0).
pub(crate) const B: [f64; 7] = [A[6][0], A[6][1], A[6][2], A[6][3], A[6][4], A[6][5], 0.0];

/// Error weights b − b̂ (b̂ of order 4), each written as one fraction.
pub(crate) const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Weights of the dense output's last coefficient (Hairer et al., contd5).
pub(crate) const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];
