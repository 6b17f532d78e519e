//! The implicit constants of the [`CostModel`] from measured frames: each frame's integration
//! time `t` against its work, `t = T g (N c_newton + F c_factor) + L (c_cg + T c_cg_tet) +
//! E (c_energy + R c_partner)` with `g = (T/1000)^α` (see `rapier_fvm::integrate::CostModel`): for each `α`
//! from 0 to 1 in steps of [`EXPONENT_STEP`], the non-negative least squares of the relative
//! residuals `(prediction − t)/t` over every frame; the `α` of the smallest sum is kept.

use rapier_fvm::integrate::CostModel;

/// The step (dimensionless) of the size exponents tried.
const EXPONENT_STEP: f64 = 0.05;

/// The constants fitted: per Newton iteration, factorization, energy evaluation, energy
/// evaluation per rigid partner, conjugate gradient iteration and its tetrahedron.
const CONSTANTS: usize = 6;

/// One implicit frame of a body: its integration time and work.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ImplicitFrame {
    /// Seconds of the body's integration (the automatic report's).
    pub seconds: f64,
    /// The body's tetrahedra.
    pub tets: f64,
    /// Newton iterations.
    pub newton_iterations: f64,
    /// Numeric factorizations.
    pub factorizations: f64,
    /// Conjugate gradient iterations.
    pub linear_iterations: f64,
    /// Evaluations of the incremental potential's energy.
    pub energy_evaluations: f64,
    /// Dynamic rigid bodies touched at the frame's start.
    pub rigid_partners: f64,
}

impl ImplicitFrame {
    /// The frame's work per constant of [`fit`], at size exponent `exponent`.
    fn columns(&self, exponent: f64) -> [f64; CONSTANTS] {
        let sized = self.tets * (self.tets / 1000.0).powf(exponent);
        [
            sized * self.newton_iterations,
            sized * self.factorizations,
            self.energy_evaluations,
            self.energy_evaluations * self.rigid_partners,
            self.linear_iterations,
            self.linear_iterations * self.tets,
        ]
    }
}

/// The implicit constants fitted to `frames` (those of the stable Neo-Hookean model), and the
/// corotated Newton iteration from `corotated` frames against `paired` ones, the same case with
/// the stable Neo-Hookean model: the Neo-Hookean iteration plus what the corotated frames took
/// beyond the paired ones per (sized) Newton iteration, so that the fit's own error cancels;
/// the other constants are [`CostModel::default`]'s.
pub fn fit(
    frames: &[ImplicitFrame],
    (corotated, paired): (&[ImplicitFrame], &[ImplicitFrame]),
) -> CostModel {
    let steps = (1.0 / EXPONENT_STEP).round() as usize;
    let (exponent, constants) = (0..=steps)
        .map(|k| {
            let exponent = k as f64 * EXPONENT_STEP;
            let constants = fit_non_negative(frames, exponent);
            (exponent, constants, residual(frames, exponent, &constants))
        })
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .map(|(exponent, constants, _)| (exponent, constants))
        .unwrap_or((0.0, [0.0; CONSTANTS]));
    let [newton, factorization, energy, partner, cg_iteration, cg_tet] = constants;
    let seconds = |frames: &[ImplicitFrame]| frames.iter().map(|f| f.seconds).sum::<f64>();
    let sized_iterations: f64 = corotated.iter().map(|f| f.columns(exponent)[0]).sum();
    let newton_corotated = if sized_iterations > 0.0 && !paired.is_empty() {
        (newton + (seconds(corotated) - seconds(paired)) / sized_iterations).max(0.0)
    } else {
        newton
    };
    CostModel {
        newton_tet: newton,
        newton_size_exponent: exponent,
        newton_tet_corotated: newton_corotated,
        factorization_tet: factorization,
        energy_evaluation: energy,
        partner_evaluation: partner,
        conjugate_gradient_iteration: cg_iteration,
        conjugate_gradient_tet: cg_tet,
        ..CostModel::default()
    }
}

/// The sum of the squared relative residuals of `constants` over `frames`.
fn residual(frames: &[ImplicitFrame], exponent: f64, constants: &[f64; CONSTANTS]) -> f64 {
    (frames.iter().filter(|f| f.seconds > 0.0))
        .map(|f| {
            let predicted: f64 = (f.columns(exponent).iter().zip(constants))
                .map(|(w, c)| w * c)
                .sum();
            ((predicted - f.seconds) / f.seconds).powi(2)
        })
        .sum()
}

/// The non-negative least-squares constants at `exponent`: a constant that comes out negative
/// is set to zero and the rest fitted again.
fn fit_non_negative(frames: &[ImplicitFrame], exponent: f64) -> [f64; CONSTANTS] {
    let mut free = [true; CONSTANTS];
    loop {
        let fitted = least_squares(frames, exponent, free);
        match (0..CONSTANTS).find(|&k| free[k] && fitted[k] < 0.0) {
            Some(k) => free[k] = false,
            None => return fitted,
        }
    }
}

/// The least-squares constants of the relative residuals with those not `free` zero: the
/// normal equations, solved by Gaussian elimination with partial pivoting; a constant with no
/// work to fit (or a singular system) is zero.
fn least_squares(
    frames: &[ImplicitFrame],
    exponent: f64,
    free: [bool; CONSTANTS],
) -> [f64; CONSTANTS] {
    const RHS: usize = CONSTANTS;
    let mut normal = [[0.0f64; CONSTANTS + 1]; CONSTANTS];
    for frame in frames.iter().filter(|f| f.seconds > 0.0) {
        let row = frame.columns(exponent).map(|w| w / frame.seconds);
        for i in 0..CONSTANTS {
            for j in 0..CONSTANTS {
                normal[i][j] += row[i] * row[j];
            }
            normal[i][RHS] += row[i];
        }
    }
    let unknowns: Vec<usize> = (0..CONSTANTS)
        .filter(|&k| free[k] && normal[k][k] > 0.0)
        .collect();
    let n = unknowns.len();
    let mut system: Vec<Vec<f64>> = (unknowns.iter())
        .map(|&i| {
            let mut row: Vec<f64> = unknowns.iter().map(|&j| normal[i][j]).collect();
            row.push(normal[i][RHS]);
            row
        })
        .collect();
    for pivot in 0..n {
        let best = (pivot..n)
            .max_by(|&x, &y| system[x][pivot].abs().total_cmp(&system[y][pivot].abs()))
            .unwrap_or(pivot);
        system.swap(pivot, best);
        for row in pivot + 1..n {
            let factor = system[row][pivot] / system[pivot][pivot];
            for col in pivot..=n {
                system[row][col] -= factor * system[pivot][col];
            }
        }
    }
    let mut solution = vec![0.0; n];
    for row in (0..n).rev() {
        let known: f64 = (row + 1..n)
            .map(|col| system[row][col] * solution[col])
            .sum();
        solution[row] = (system[row][n] - known) / system[row][row];
    }
    let mut constants = [0.0; CONSTANTS];
    for (k, value) in unknowns.into_iter().zip(solution) {
        constants[k] = if value.is_finite() { value } else { 0.0 };
    }
    constants
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_made_by_the_model_give_back_its_constants_and_exponent() {
        // Frames computed from known constants and α = 0.35 (a multiple of the step): the fit
        // must recover them to 1e-9 relative (round-off in the normal equations), and the
        // corotated iteration from frames dearer by a known amount.
        let truth = [3e-7, 9e-7, 5e-5, 8e-6, 2e-5, 8e-9];
        let exponent = 0.35;
        let mut frames = Vec::new();
        for (k, tets) in [320.0, 1080.0, 5000.0, 20480.0].into_iter().enumerate() {
            for n in 1..=4 {
                let frame = ImplicitFrame {
                    seconds: 0.0,
                    tets,
                    newton_iterations: n as f64,
                    factorizations: ((n + k) % 3) as f64,
                    linear_iterations: (10 * ((n + 2 * k) % 4)) as f64,
                    energy_evaluations: (2 * n + k % 2) as f64,
                    rigid_partners: ((n + k) % 3) as f64,
                };
                let seconds = (frame.columns(exponent).iter().zip(truth))
                    .map(|(w, c)| w * c)
                    .sum();
                frames.push(ImplicitFrame { seconds, ..frame });
            }
        }
        // The corotated frames: the first four frames again, each dearer by 2e-7 s per sized
        // Newton iteration; its iteration must come out the fitted one plus that.
        let paired = &frames[..4];
        let corotated: Vec<ImplicitFrame> = (paired.iter())
            .map(|f| ImplicitFrame {
                seconds: f.seconds + 2e-7 * f.columns(exponent)[0],
                ..*f
            })
            .collect();
        let cost = fit(&frames, (&corotated, paired));
        assert!((cost.newton_tet_corotated - (truth[0] + 2e-7)).abs() <= 1e-9 * 5e-7);
        assert!((cost.newton_size_exponent - exponent).abs() < 1e-12);
        let fitted = [
            cost.newton_tet,
            cost.factorization_tet,
            cost.energy_evaluation,
            cost.partner_evaluation,
            cost.conjugate_gradient_iteration,
            cost.conjugate_gradient_tet,
        ];
        for (f, t) in fitted.iter().zip(truth) {
            assert!((f - t).abs() <= 1e-9 * t, "{fitted:?} against {truth:?}");
        }
    }
}
