//! Probes bound to the world's bodies, sampled after every frame.

use super::build::Simulation;
use crate::output::TimeSeries;
use crate::scene::probe::{Component, EnergyKind, ProbeKind, ProbeSpec};
use crate::scene::{SceneError, SceneSource};
use rapier_fvm::body::DeformableBody;
use rapier_fvm::glamx::DVec3;
use rapier_fvm::load::LoadHandle;

/// A probe and the samples taken so far.
#[derive(Debug, Clone)]
pub struct Probe {
    /// What it reads.
    target: Target,
    /// The samples: name, unit and `(time (s), value)` pairs.
    pub series: TimeSeries,
    /// The kind, for the report.
    pub kind: ProbeKind,
}

/// What a probe reads, by index into the simulation's bodies.
#[derive(Debug, Clone, Copy)]
enum Target {
    Displacement {
        soft: usize,
        node: usize,
        component: Component,
    },
    Position {
        rigid: usize,
        component: Component,
    },
    Velocity {
        rigid: usize,
        component: Component,
    },
    ContactForce {
        rigid: usize,
        soft: Option<usize>,
        component: Component,
    },
    ContactForceOnSoft {
        soft: usize,
        rigid: Option<usize>,
        component: Component,
    },
    Energy {
        soft: Option<usize>,
        energy: EnergyKind,
    },
    Momentum {
        soft: Option<usize>,
        component: Component,
    },
    AngularMomentum {
        soft: Option<usize>,
        component: Component,
    },
    Cavity {
        soft: usize,
        load: LoadHandle,
        pressure: bool,
    },
}

impl Probe {
    /// Binds `spec` (checked with the scene, at key path `key`) to the bodies of `simulation`.
    ///
    /// # Errors
    /// A [`SceneError`] if a body it names is not in the simulation.
    pub(crate) fn bind(
        spec: &ProbeSpec,
        key: &str,
        source: &SceneSource,
        simulation: &Simulation,
    ) -> Result<Self, SceneError> {
        let soft = |name: &Option<String>| -> Result<Option<usize>, SceneError> {
            name.as_deref()
                .map(|n| {
                    simulation
                        .soft_index(n)
                        .ok_or_else(|| source.error(&format!("{key}.body"), "no such soft body"))
                })
                .transpose()
        };
        let rigid = || -> Result<Option<usize>, SceneError> {
            spec.rigid
                .as_deref()
                .map(|n| {
                    simulation
                        .rigid_index(n)
                        .ok_or_else(|| source.error(&format!("{key}.rigid"), "no such rigid body"))
                })
                .transpose()
        };
        let missing = |field: &str| source.error(key, format!("the probe needs `{field}`"));
        let one_rigid = || rigid()?.ok_or_else(|| missing("rigid"));
        let component = spec.component;
        let target = match spec.kind {
            ProbeKind::Displacement => {
                let soft = soft(&spec.body)?.ok_or_else(|| missing("body"))?;
                let point = spec.point.ok_or_else(|| missing("point"))?;
                let body = &simulation.world.soft_bodies[simulation.soft[soft].handle];
                let node = body.mesh().nearest_node(DVec3::from_array(point)) as usize;
                Target::Displacement {
                    soft,
                    node,
                    component,
                }
            }
            ProbeKind::Position => Target::Position {
                rigid: one_rigid()?,
                component,
            },
            ProbeKind::Velocity => Target::Velocity {
                rigid: one_rigid()?,
                component,
            },
            ProbeKind::ContactForce => Target::ContactForce {
                rigid: one_rigid()?,
                soft: soft(&spec.body)?,
                component,
            },
            ProbeKind::ContactForceOnSoft => Target::ContactForceOnSoft {
                soft: soft(&spec.body)?.ok_or_else(|| missing("body"))?,
                rigid: rigid()?,
                component,
            },
            ProbeKind::Energy => Target::Energy {
                soft: soft(&spec.body)?,
                energy: spec.energy.ok_or_else(|| missing("energy"))?,
            },
            ProbeKind::Momentum => Target::Momentum {
                soft: soft(&spec.body)?,
                component,
            },
            ProbeKind::AngularMomentum => Target::AngularMomentum {
                soft: soft(&spec.body)?,
                component,
            },
            ProbeKind::CavityPressure | ProbeKind::CavityVolume => {
                let soft = soft(&spec.body)?.ok_or_else(|| missing("body"))?;
                let index = spec.load.ok_or_else(|| missing("load"))?;
                let load = LoadHandle(u32::try_from(index).unwrap_or(u32::MAX));
                let body = &simulation.world.soft_bodies[simulation.soft[soft].handle];
                let encloses = (body.load(load)).and_then(|l| l.enclosed_volume(body.positions()));
                if encloses.is_none() {
                    return Err(source.error(
                        &format!("{key}.load"),
                        "the body has no pressure or chamber load of that number",
                    ));
                }
                Target::Cavity {
                    soft,
                    load,
                    pressure: spec.kind == ProbeKind::CavityPressure,
                }
            }
        };
        Ok(Self {
            target,
            kind: spec.kind,
            series: TimeSeries {
                name: spec.name.clone(),
                unit: spec.kind.unit().to_owned(),
                samples: Vec::new(),
            },
        })
    }

    /// The probe's value now.
    pub(crate) fn value(&self, simulation: &Simulation) -> f64 {
        let world = &simulation.world;
        let rigid_body = |rigid: usize| world.physics.bodies.get(simulation.rigid[rigid].handle);
        match self.target {
            Target::Displacement {
                soft,
                node,
                component,
            } => {
                let entry = &simulation.soft[soft];
                let x = world.soft_bodies[entry.handle].positions()[node];
                pick(x - entry.rest[node], component)
            }
            Target::Position { rigid, component } => {
                rigid_body(rigid).map_or(f64::NAN, |b| pick(b.translation().as_dvec3(), component))
            }
            Target::Velocity { rigid, component } => {
                rigid_body(rigid).map_or(f64::NAN, |b| pick(b.linvel().as_dvec3(), component))
            }
            Target::ContactForce {
                rigid,
                soft,
                component,
            } => pick(load(simulation, soft, Some(rigid)), component),
            Target::ContactForceOnSoft {
                soft,
                rigid,
                component,
            } => pick(-load(simulation, Some(soft), rigid), component),
            Target::Energy { soft, energy } => soft_energy(simulation, soft, energy),
            Target::Momentum { soft, component } => {
                let momentum = soft_bodies(simulation, soft).map(|b| b.linear_momentum());
                pick(momentum.sum(), component)
            }
            Target::AngularMomentum { soft, component } => {
                pick(angular_momentum(simulation, soft), component)
            }
            Target::Cavity {
                soft,
                load,
                pressure,
            } => {
                let body = &world.soft_bodies[simulation.soft[soft].handle];
                let (load, x) = (body.load(load), body.positions());
                let value = if pressure {
                    load.and_then(|l| l.pressure_at(x))
                } else {
                    load.and_then(|l| l.enclosed_volume(x))
                };
                value.unwrap_or(f64::NAN)
            }
        }
    }

    /// Takes a sample at time `t` (s).
    pub(crate) fn sample(&mut self, t: f64, simulation: &Simulation) {
        let value = self.value(simulation);
        self.series.samples.push((t, value));
    }
}

/// The soft bodies of `simulation`: body `soft`, or every one.
fn soft_bodies(
    simulation: &Simulation,
    soft: Option<usize>,
) -> impl Iterator<Item = &DeformableBody> {
    (simulation.soft.iter().enumerate())
        .filter(move |(i, _)| soft.is_none_or(|s| s == *i))
        .map(|(_, entry)| &simulation.world.soft_bodies[entry.handle])
}

/// The mean force (N) soft body `soft` (or every one) exerted on rigid body `rigid` (or every
/// one) over the last frame, through its contacts and attachments.
fn load(simulation: &Simulation, soft: Option<usize>, rigid: Option<usize>) -> DVec3 {
    let chosen = |index: Option<usize>, i: usize| index.is_none_or(|s| s == i);
    let mut force = DVec3::ZERO;
    for (i, soft_entry) in simulation.soft.iter().enumerate() {
        for (j, rigid_entry) in simulation.rigid.iter().enumerate() {
            if chosen(soft, i) && chosen(rigid, j) {
                force += (simulation.world)
                    .load_on(soft_entry.handle, rigid_entry.handle)
                    .0;
            }
        }
    }
    force
}

/// The `energy` (J) of soft body `soft`, or of every one.
fn soft_energy(simulation: &Simulation, soft: Option<usize>, energy: EnergyKind) -> f64 {
    let gravity = simulation.world.physics.gravity.as_dvec3();
    soft_bodies(simulation, soft)
        .map(|body| {
            let elastic = || body.elastic_energy();
            let kinetic = || body.kinetic_energy();
            let potential = || body.gravity_potential_energy(gravity);
            match energy {
                EnergyKind::Elastic => elastic(),
                EnergyKind::Kinetic => kinetic(),
                EnergyKind::Gravity => potential(),
                EnergyKind::Total => elastic() + kinetic() + potential(),
            }
        })
        .sum()
}

/// The angular momentum (N m s) of soft body `soft` about its centre of mass, or of every one
/// about their common centre of mass `C`: `Σ (L_b + (c_b - C) × p_b)` over the bodies `b`, each
/// of angular momentum `L_b` about its centre of mass `c_b` and linear momentum `p_b`.
fn angular_momentum(simulation: &Simulation, soft: Option<usize>) -> DVec3 {
    let (mut weighted, mut mass) = (DVec3::ZERO, 0.0);
    for body in soft_bodies(simulation, soft) {
        weighted += body.center_of_mass() * body.total_mass();
        mass += body.total_mass();
    }
    let center = weighted / mass;
    soft_bodies(simulation, soft)
        .map(|body| {
            body.angular_momentum() + (body.center_of_mass() - center).cross(body.linear_momentum())
        })
        .sum()
}

/// The `component` of `v`.
fn pick(v: DVec3, component: Component) -> f64 {
    match component {
        Component::X => v.x,
        Component::Y => v.y,
        Component::Z => v.z,
        Component::Norm => v.length(),
    }
}
