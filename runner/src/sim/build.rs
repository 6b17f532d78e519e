//! A [`Scene`] made into a world: soft bodies meshed, placed, set moving, pinned and attached,
//! rigid bodies and their colliders inserted, probes bound to the bodies they read.

use super::loads::{DrivenLoad, add_loads, build_loads};
use super::materials::{element_centroids, region_materials};
use super::meshes::BodyMeshes;
use super::probe::Probe;
use super::regions::BodyRegions;
use crate::output::{RigidBodySnapshot, Snapshot, SoftBodySnapshot};
use crate::scene::budget::MemoryUse;
use crate::scene::rigid_body::{RigidBodySpec, RigidKind, ShapeSpec};
use crate::scene::soft_body::SoftBodySpec;
use crate::scene::{Scene, SceneError, SceneSource};
use rapier_fvm::body::{DeformableBodyBuilder, DeformableBodyHandle};
use rapier_fvm::coupling::SleepSettings;
use rapier_fvm::glamx::{DVec3, Vec3};
use rapier_fvm::mesh::import::surface;
use rapier_fvm::world::FvmWorld;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle, SharedShape};

/// A soft body of the world and what the runner keeps about it.
#[derive(Debug, Clone)]
pub struct SoftEntry {
    /// Its name in the scene.
    pub name: String,
    /// Its material label (colour in the pictures).
    pub label: String,
    /// Its handle in the world.
    pub handle: DeformableBodyHandle,
    /// Its world positions before the first step (m): displacements are measured from them.
    pub rest: Vec<DVec3>,
    /// Its loads that keyframes drive.
    pub loads: Vec<DrivenLoad>,
}

/// A rigid body of the world.
#[derive(Debug, Clone)]
pub struct RigidEntry {
    /// Its name in the scene.
    pub name: String,
    /// Its handle in the world.
    pub handle: RigidBodyHandle,
    /// Its description (kind, keyframes).
    pub spec: RigidBodySpec,
}

/// The world a scene describes, and the names of its bodies.
pub struct Simulation {
    /// The world.
    pub world: FvmWorld,
    /// The soft bodies, in scene order.
    pub soft: Vec<SoftEntry>,
    /// The rigid bodies, in scene order.
    pub rigid: Vec<RigidEntry>,
    /// The probes, in scene order.
    pub probes: Vec<Probe>,
}

impl Simulation {
    /// Builds the world of `scene`.
    ///
    /// # Errors
    /// A [`SceneError`] at the key whose mesh file cannot be read, whose region holds no node,
    /// whose mesh takes the soft bodies past the scene's
    /// [`MemoryBudget`](crate::scene::MemoryBudget) (counted as the meshes are read, before a
    /// body is built of them), or that the library refuses (a mesh with sliver elements, say).
    pub fn build(scene: &Scene) -> Result<Self, SceneError> {
        let source = &scene.source;
        let mut world = FvmWorld::default();
        world.physics.gravity = DVec3::from_array(scene.world.gravity).as_vec3();
        world.physics.integration_parameters.dt = scene.world.dt as f32;
        world.coupling.substeps = scene.world.coupling_substeps;
        world.coupling.sleep = SleepSettings {
            speed_threshold: scene.world.sleep_speed,
            time_until_sleep: scene.world.time_until_sleep,
        };
        world.coupling.contact = scene.contact.settings();
        world.coupling.integrator = scene.integrator.integrator();
        let mut rigid = Vec::new();
        for (i, spec) in scene.rigid_body.iter().enumerate() {
            let handle = insert_rigid(&mut world, spec, &format!("rigid_body[{i}]"), source)?;
            rigid.push(RigidEntry {
                name: spec.name.clone(),
                handle,
                spec: spec.clone(),
            });
        }
        let mut soft = Vec::new();
        let mut memory = MemoryUse::new(scene.budget);
        for (i, spec) in scene.soft_body.iter().enumerate() {
            let key = format!("soft_body[{i}]");
            soft.push(insert_soft(
                &mut world,
                spec,
                &rigid,
                (&key, source),
                &mut memory,
            )?);
        }
        let mut simulation = Self {
            world,
            soft,
            rigid,
            probes: Vec::new(),
        };
        for (i, spec) in scene.probe.iter().enumerate() {
            let probe = Probe::bind(spec, &format!("probe[{i}]"), source, &simulation)?;
            simulation.probes.push(probe);
        }
        Ok(simulation)
    }

    /// The index of the soft body named `name`.
    pub fn soft_index(&self, name: &str) -> Option<usize> {
        self.soft.iter().position(|s| s.name == name)
    }

    /// The index of the rigid body named `name`.
    pub fn rigid_index(&self, name: &str) -> Option<usize> {
        self.rigid.iter().position(|r| r.name == name)
    }

    /// The world now as plain data at simulated time `time` (s), half-spaces and huge cuboids
    /// drawn as patches of half size `patch` (m).
    pub fn snapshot(&self, time: f64, patch: f64) -> Snapshot {
        Snapshot {
            time,
            soft_bodies: (self.soft.iter())
                .map(|entry| {
                    let body = &self.world.soft_bodies[entry.handle];
                    SoftBodySnapshot::capture(&entry.name, &entry.label, body, &entry.rest)
                })
                .collect(),
            rigid_bodies: (self.rigid.iter())
                .filter_map(|entry| {
                    RigidBodySnapshot::of_body(
                        &entry.name,
                        &self.world.physics,
                        entry.handle,
                        patch,
                    )
                })
                .collect(),
        }
    }

    /// Samples every probe at time `t` (s).
    pub fn sample_probes(&mut self, t: f64) {
        let mut probes = std::mem::take(&mut self.probes);
        for probe in &mut probes {
            probe.sample(t, self);
        }
        self.probes = probes;
    }

    /// Sets every keyframed load to its value at time `t` (s), for the coming frame.
    ///
    /// # Errors
    /// A [`SceneError`] at a load the library refuses the value of (the scene's check makes
    /// every keyframe's value one it takes, and so every value between two).
    pub fn drive_loads(&mut self, t: f64, source: &SceneSource) -> Result<(), SceneError> {
        for entry in &self.soft {
            let Some(body) = self.world.soft_bodies.get_mut(entry.handle) else {
                continue;
            };
            for load in &entry.loads {
                (body.set_load(load.handle, load.schedule.at(t)))
                    .map_err(|e| source.error(&load.key, e.to_string()))?;
            }
        }
        Ok(())
    }

    /// Tells every kinematic body where its keyframes put it at time `t` (s); rapier moves it
    /// there over the coming frame.
    pub fn drive_kinematic(&mut self, t: f64) {
        for entry in &self.rigid {
            if let Some(x) = entry.spec.keyframe_translation(t)
                && let Some(body) = self.world.physics.bodies.get_mut(entry.handle)
            {
                body.set_next_kinematic_translation(DVec3::from_array(x).as_vec3());
            }
        }
    }
}

/// Inserts a rigid body and its collider.
fn insert_rigid(
    world: &mut FvmWorld,
    spec: &RigidBodySpec,
    key: &str,
    source: &SceneSource,
) -> Result<RigidBodyHandle, SceneError> {
    let shape = shape(spec, key, source)?;
    let translation = spec.keyframe_translation(0.0).unwrap_or(spec.translation);
    let v = |a: [f64; 3]| DVec3::from_array(a).as_vec3();
    let body = match spec.kind {
        RigidKind::Fixed => RigidBodyBuilder::fixed(),
        RigidKind::Dynamic => RigidBodyBuilder::dynamic(),
        RigidKind::Kinematic => RigidBodyBuilder::kinematic_position_based(),
    }
    .translation(v(translation))
    .rotation(v(spec.rotation))
    .linvel(v(spec.linvel))
    .angvel(v(spec.angvel));
    let mut collider = ColliderBuilder::new(shape)
        .friction(spec.friction as f32)
        .restitution(spec.restitution as f32);
    collider = match spec.mass {
        Some(mass) => collider.mass(mass as f32),
        None => collider.density(spec.density.unwrap_or(1000.0) as f32),
    };
    Ok(world.physics.insert(body, collider).0)
}

/// The collider shape of `spec`, loading a triangle mesh file if needed.
fn shape(spec: &RigidBodySpec, key: &str, source: &SceneSource) -> Result<SharedShape, SceneError> {
    let f = |x: f64| x as f32;
    Ok(match &spec.shape {
        ShapeSpec::Ball { radius } => SharedShape::ball(f(*radius)),
        ShapeSpec::Cuboid { half_extents: h } => SharedShape::cuboid(f(h[0]), f(h[1]), f(h[2])),
        ShapeSpec::Capsule {
            half_height,
            radius,
        } => SharedShape::capsule_y(f(*half_height), f(*radius)),
        ShapeSpec::Cylinder {
            half_height,
            radius,
        } => SharedShape::cylinder(f(*half_height), f(*radius)),
        ShapeSpec::HalfSpace { normal } => {
            SharedShape::halfspace(DVec3::from_array(*normal).normalize().as_vec3())
        }
        ShapeSpec::Trimesh { file, scale } => {
            let key = format!("{key}.trimesh.file");
            let path = source.folder().join(file);
            let name = path.display().to_string();
            let data = std::fs::read(&path)
                .map_err(|e| source.error(&key, format!("cannot read {name}: {e}")))?;
            let is_stl = path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("stl"));
            let surface = if is_stl {
                surface::parse_stl(&data, &name, *scale)
            } else {
                surface::parse_obj(&data, &name, *scale)
            }
            .map_err(|e| source.error(&key, e.to_string()))?;
            let vertices: Vec<Vec3> = surface.vertices.iter().map(|p| p.as_vec3()).collect();
            SharedShape::trimesh(vertices, surface.triangles)
                .map_err(|e| source.error(&key, format!("{name}: {e}")))?
        }
    })
}

/// Builds, inserts and attaches a soft body, `key` in the scene of `source`, once its meshes
/// fit in `memory`.
fn insert_soft(
    world: &mut FvmWorld,
    spec: &SoftBodySpec,
    rigid: &[RigidEntry],
    (key, source): (&str, &SceneSource),
    memory: &mut MemoryUse,
) -> Result<SoftEntry, SceneError> {
    let BodyMeshes {
        mesh,
        quadratic,
        cage,
        embedded,
        regions,
        path,
    } = BodyMeshes::build(spec, (key, source), memory)?;
    let library = |key: String| move |e: rapier_fvm::Error| source.error(&key, e.to_string());
    let material = spec
        .material
        .material()
        .map_err(library(format!("{key}.material")))?;
    let BodyRegions {
        pinned,
        velocities,
        attachments,
    } = BodyRegions::select(spec, (&mesh, &regions, &path), rigid, (key, source))?;
    let loads = build_loads(&spec.loads, (&mesh, &regions, &path), (key, source))?;
    let centroids = match (&quadratic, &cage) {
        (Some(q), _) => element_centroids(mesh.positions(), q.elements().iter().map(|e| &e[..])),
        (_, Some(c)) => element_centroids(mesh.positions(), c.elements().iter().map(|e| &e[..])),
        _ => element_centroids(mesh.positions(), mesh.tets().iter().map(|t| &t[..])),
    };
    let materials = region_materials(spec, &centroids, (&regions, &path), (key, source))?;
    let mut builder = match (quadratic, cage) {
        (Some(quadratic), _) => DeformableBodyBuilder::quadratic(quadratic, material),
        (_, Some(cage)) => DeformableBodyBuilder::quadratic_hex(cage, material),
        _ => DeformableBodyBuilder::new(mesh, material),
    };
    if let Some(fine) = embedded {
        builder = builder.embedded(fine);
    }
    if let Some(tolerance) = spec.rigid_stand_in {
        builder = builder.rigid_stand_in(tolerance);
    }
    let mut builder = builder
        .translation(DVec3::from_array(spec.translation))
        .rotation(DVec3::from_array(spec.rotation))
        .linvel(DVec3::from_array(spec.linvel))
        .angvel(DVec3::from_array(spec.angvel))
        .pinned_nodes(pinned)
        .friction(spec.friction)
        .self_contact(spec.self_contact)
        .volumetric(spec.volumetric.treatment());
    for (nodes, linvel) in velocities {
        builder = builder.nodes_linvel(nodes, linvel);
    }
    for (elements, material) in materials {
        builder = builder.region_material(elements, material);
    }
    if let Some(damping) = &spec.damping {
        builder = builder.damping(
            damping
                .damping(&material)
                .map_err(library(format!("{key}.damping")))?,
        );
    }
    let mut body = builder.build().map_err(library(key.to_owned()))?;
    let driven = add_loads(&mut body, loads, source)?;
    let rest = body.positions().to_vec();
    let handle = world.soft_bodies.insert(body);
    for attachment in attachments {
        (world.attach(handle, attachment.nodes, attachment.rigid))
            .map_err(library(attachment.key))?;
    }
    Ok(SoftEntry {
        name: spec.name.clone(),
        label: spec.material.label(),
        handle,
        rest,
        loads: driven,
    })
}
