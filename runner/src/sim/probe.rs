//! Probes bound to the world's bodies, sampled after every frame.

use super::build::Simulation;
use crate::output::TimeSeries;
use crate::scene::probe::{Component, EnergyKind, ProbeKind, ProbeSpec};
use crate::scene::{SceneError, SceneSource};
use rapier_fvm::glamx::DVec3;

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
    Energy {
        soft: Option<usize>,
        energy: EnergyKind,
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
        let rigid = || -> Result<usize, SceneError> {
            spec.rigid
                .as_deref()
                .and_then(|n| simulation.rigid_index(n))
                .ok_or_else(|| source.error(&format!("{key}.rigid"), "no such rigid body"))
        };
        let component = spec.component;
        let missing = |field: &str| source.error(key, format!("the probe needs `{field}`"));
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
                rigid: rigid()?,
                component,
            },
            ProbeKind::Velocity => Target::Velocity {
                rigid: rigid()?,
                component,
            },
            ProbeKind::ContactForce => Target::ContactForce {
                rigid: rigid()?,
                soft: soft(&spec.body)?,
                component,
            },
            ProbeKind::Energy => Target::Energy {
                soft: soft(&spec.body)?,
                energy: spec.energy.ok_or_else(|| missing("energy"))?,
            },
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
            } => {
                let handle = simulation.rigid[rigid].handle;
                let force = (simulation.soft.iter().enumerate())
                    .filter(|(i, _)| soft.is_none_or(|s| s == *i))
                    .map(|(_, entry)| world.load_on(entry.handle, handle).0)
                    .sum();
                pick(force, component)
            }
            Target::Energy { soft, energy } => {
                let gravity = world.physics.gravity.as_dvec3();
                (simulation.soft.iter().enumerate())
                    .filter(|(i, _)| soft.is_none_or(|s| s == *i))
                    .map(|(_, entry)| {
                        let body = &world.soft_bodies[entry.handle];
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
        }
    }

    /// Takes a sample at time `t` (s).
    pub(crate) fn sample(&mut self, t: f64, simulation: &Simulation) {
        let value = self.value(simulation);
        self.series.samples.push((t, value));
    }
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
