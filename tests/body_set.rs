//! The soft-body set: generational handles, and stepping every body with each body's outcome
//! reported against its handle.

use rapier_fvm::prelude::*;

fn ball(young: f64) -> DeformableBody {
    let material = Material::new(MaterialModel::StableNeoHookean, young, 0.4, 1000.0).unwrap();
    DeformableBodyBuilder::new(mesh::sphere(0.1, 4).unwrap(), material)
        .build()
        .unwrap()
}

#[test]
fn handles_stay_valid_until_removal_and_never_alias_a_reused_slot() {
    let mut set = DeformableBodySet::new();
    let a = set.insert(ball(1e5));
    let b = set.insert(ball(2e5));
    assert_eq!(set.len(), 2);
    assert_eq!(set[b].material().elasticity().young_modulus, 2e5);
    let removed = set.remove(a).unwrap();
    assert!(set.remove(a).is_none());
    let c = set.insert(removed);
    assert_eq!(
        c.into_raw_parts().0,
        a.into_raw_parts().0,
        "the free slot is reused"
    );
    assert!(set.get(a).is_none() && set.contains(c) && set.contains(b));
    let handles: Vec<DeformableBodyHandle> = set.iter().map(|(h, _)| h).collect();
    assert_eq!(handles, vec![c, b]);
}

#[test]
fn stepping_a_set_reports_each_body_and_keeps_a_failed_one_unchanged() {
    let mut set = DeformableBodySet::new();
    let good = set.insert(ball(1e5));
    let bad = set.insert(ball(1e5));
    set[bad].velocities_mut()[0].x = f64::NAN;
    let before = set[bad].positions().to_vec();
    let integrator = AutomaticIntegrator::default();
    // One set of constraints and solver caches per body, kept beside it.
    let mut beside: Vec<(BodyConstraints, SolverWorkspace)> = set
        .iter()
        .map(|_| (BodyConstraints::new(), SolverWorkspace::new()))
        .collect();
    let outcomes: Vec<_> = set
        .iter_mut()
        .zip(&mut beside)
        .map(|((handle, body), (constraints, workspace))| {
            let gravity = DVec3::new(0.0, -9.81, 0.0);
            let outcome = integrator.step(body, constraints, workspace, 1.0 / 60.0, gravity);
            (handle, outcome)
        })
        .collect();
    assert_eq!(outcomes.len(), 2);
    for (handle, outcome) in outcomes {
        if handle == good {
            assert!(outcome.is_ok());
        } else {
            assert_eq!(handle, bad);
            assert!(
                matches!(outcome, Err(Error::NonFiniteState { .. })),
                "{outcome:?}"
            );
        }
    }
    assert_eq!(set[bad].positions(), &before[..]);
    assert!(set[good].linear_momentum().y < 0.0, "the good ball fell");
}
