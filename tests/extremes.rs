//! The extremes: a subset of the table of `examples/extremes.rs` (both scenes, soft to stiff,
//! auxetic to nearly incompressible, small to large frame steps, automatic choice of integrator). Every case
//! must be stable (finite, energy never above its start by more than 1e-3 m g L) or refused with a
//! typed error; none may be unstable.

#[path = "../examples/extremes.rs"]
mod extremes;

use extremes::{Outcome, SCENES, run_case};
use rapier_fvm::Error;

#[test]
fn extreme_materials_and_steps_are_stable_or_refused() {
    let mut unstable = Vec::new();
    for scene in SCENES {
        for young in [1e3, 1e7, 1e11] {
            for poisson in [-0.9, 0.3, 0.4999] {
                for frame_dt in [1e-4, 1.0 / 30.0] {
                    let case = run_case(scene, young, poisson, frame_dt, 10);
                    let label = format!(
                        "{:?} E {:e} nu {} dt {:.2e}",
                        case.scene, case.young, case.poisson, case.frame_dt
                    );
                    println!("{label}: {:?}, {}", case.outcome, case.integrator);
                    match case.outcome {
                        Outcome::Unstable(why) => unstable.push(format!("{label}: {why}")),
                        // The implicit matrix M/h² + K (projected) is positive definite for any
                        // finite state: failing to factor it means a blow-up, not a refusal.
                        Outcome::Refused(Error::IndefiniteStiffness { .. }) => {
                            unstable.push(format!("{label}: implicit matrix not positive definite"))
                        }
                        _ => {}
                    }
                }
            }
        }
    }
    assert!(unstable.is_empty(), "unstable cases: {unstable:#?}");
}
