//! Butcher tableaus of the explicit Runge–Kutta methods used by the driver.

/// An explicit Runge–Kutta method with `S` stages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tableau<const S: usize> {
    /// Name used in error messages.
    pub name: &'static str,
    /// Nodes `c_i`.
    pub c: [f64; S],
    /// Stage matrix `a_ij` (strictly lower triangular).
    pub a: [[f64; S]; S],
    /// Weights `b_i` of the propagated solution.
    pub b: [f64; S],
    /// Error weights `b_i - b̂_i` of the embedded pair (zero: no error estimate).
    pub e: [f64; S],
    /// Dense-output weights: the continuous extension is the cubic Hermite interpolant plus
    /// `θ²(1-θ)² h Σ d_i k_i` (zero: the cubic Hermite interpolant).
    pub d: [f64; S],
    /// Order of the propagated solution.
    pub order: u32,
    /// Order of the local error estimate, `p̂ + 1` (the exponent of the step-size controller);
    /// 0 without an embedded pair.
    pub error_order: u32,
    /// First same as last: the last stage is `f(t + h, y_{n+1})`, reused as the next first
    /// stage.
    pub fsal: bool,
}

/// The classical fourth-order method (the paper's shooting integrator).
pub const RK4: Tableau<4> = Tableau {
    name: "rk4",
    c: [0.0, 0.5, 0.5, 1.0],
    a: [
        [0.0, 0.0, 0.0, 0.0],
        [0.5, 0.0, 0.0, 0.0],
        [0.0, 0.5, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ],
    b: [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
    e: [0.0; 4],
    d: [0.0; 4],
    order: 4,
    error_order: 0,
    fsal: false,
};

/// The Bogacki–Shampine 3(2) pair (MATLAB's `ode23`), FSAL, cubic Hermite dense output.
pub const BS3: Tableau<4> = Tableau {
    name: "ode23 (Bogacki-Shampine)",
    c: [0.0, 0.5, 0.75, 1.0],
    a: [
        [0.0, 0.0, 0.0, 0.0],
        [0.5, 0.0, 0.0, 0.0],
        [0.0, 0.75, 0.0, 0.0],
        [2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0, 0.0],
    ],
    b: [2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0, 0.0],
    e: [-5.0 / 72.0, 1.0 / 12.0, 1.0 / 9.0, -1.0 / 8.0],
    d: [0.0; 4],
    order: 3,
    error_order: 3,
    fsal: true,
};

/// The Dormand–Prince 5(4) pair (Hairer, Nørsett & Wanner, table II.5.2), FSAL, with its
/// fourth-order continuous extension.
pub const DP5: Tableau<7> = Tableau {
    name: "Dormand-Prince 5(4)",
    c: [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0],
    a: [
        [0.0; 7],
        [0.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0, 0.0],
        [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
            0.0,
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
            0.0,
        ],
        [
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
            0.0,
        ],
    ],
    b: [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
        0.0,
    ],
    e: [
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ],
    d: [
        -12715105075.0 / 11282082432.0,
        0.0,
        87487479700.0 / 32700410799.0,
        -10690763975.0 / 1880347072.0,
        701980252875.0 / 199316789632.0,
        -1453857185.0 / 822651844.0,
        69997945.0 / 29380423.0,
    ],
    order: 5,
    error_order: 5,
    fsal: true,
};
