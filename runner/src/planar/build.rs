//! A 2D scene built: its soft bodies ([`PlanarBody`]), its rapier2d world and the coupling
//! between them ([`PlanarCoupling`]), its probes, and the world as plain data for the writers
//! (the plane at z = 0).

use super::probe::PlanarProbe;
use super::scene::{
    PlanarBoxSpec, PlanarElementsSpec, PlanarIntegratorSpec, PlanarMeshSpec, PlanarRigidBodySpec,
    PlanarRigidKind, PlanarScene, PlanarShapeSpec, PlanarSoftBodySpec, PlaneSpec,
};
use crate::output::{Cells, RigidBodySnapshot, Snapshot, SoftBodySnapshot};
use crate::scene::SceneError;
use rapier_fvm::glamx::{DVec2, DVec3};
use rapier_fvm::planar::coupling::{PlanarCoupling, PlanarIntegrator};
use rapier_fvm::planar::{PlanarBody, PlanarBodyBuilder, PlaneModel, TriangleMesh};
use rapier2d::prelude::{
    ColliderBuilder, ColliderHandle, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle,
};

/// Segments of a ball's drawn outline.
const BALL_SEGMENTS: usize = 48;

/// A soft body's name, material label and starting node positions (m).
#[derive(Debug, Clone)]
pub struct PlanarSoftEntry {
    /// Its name.
    pub name: String,
    /// Its material's label (pictures).
    pub label: String,
    /// Where its nodes started (m): displacements are measured from there.
    pub start: Vec<DVec2>,
}

/// A rigid body's name, handles and shape.
#[derive(Debug, Clone)]
pub struct PlanarRigidEntry {
    /// Its name.
    pub name: String,
    /// Its handle in the rapier2d world.
    pub handle: RigidBodyHandle,
    /// Its collider.
    pub collider: ColliderHandle,
    /// Its shape as written.
    pub shape: PlanarShapeSpec,
}

/// A 2D scene ready to run.
pub struct PlanarSimulation {
    /// The rapier2d world (rigid bodies, colliders, gravity, frame step).
    pub physics: PhysicsWorld,
    /// The soft bodies, in the scene's order.
    pub bodies: Vec<PlanarBody>,
    /// How they step with the rigid bodies.
    pub coupling: PlanarCoupling,
    /// The soft bodies' names, labels and starting positions.
    pub soft: Vec<PlanarSoftEntry>,
    /// The rigid bodies.
    pub rigid: Vec<PlanarRigidEntry>,
    /// Gravity (m/s²).
    pub gravity: DVec2,
    /// The probes.
    pub probes: Vec<PlanarProbe>,
}

impl PlanarSimulation {
    /// Builds `scene`.
    ///
    /// # Errors
    /// A [`SceneError`] at the key of a mesh or material the library refuses (a polygon
    /// outline that crosses itself, say).
    pub fn build(scene: &PlanarScene) -> Result<Self, SceneError> {
        let mut physics = PhysicsWorld::default();
        let [gx, gy] = scene.world.gravity;
        physics.gravity = [gx as f32, gy as f32].into();
        physics.integration_parameters.dt = scene.world.dt as f32;
        let rigid: Vec<PlanarRigidEntry> = (scene.rigid_body.iter())
            .map(|spec| insert_rigid(&mut physics, spec))
            .collect();
        let mut bodies = Vec::new();
        let mut soft = Vec::new();
        for (i, spec) in scene.soft_body.iter().enumerate() {
            let at = |(key, message): (String, String)| {
                scene.source.error(&format!("soft_body[{i}]{key}"), message)
            };
            let body = soft_body(spec).map_err(at)?;
            soft.push(PlanarSoftEntry {
                name: spec.name.clone(),
                label: spec.material.label(),
                start: body.positions().to_vec(),
            });
            bodies.push(body);
        }
        let mut coupling = PlanarCoupling::default();
        coupling.substeps = scene.world.coupling_substeps;
        coupling.friction = scene.world.friction;
        coupling.integrator = match scene.world.integrator {
            PlanarIntegratorSpec::Explicit => PlanarIntegrator::Explicit,
            PlanarIntegratorSpec::Implicit => PlanarIntegrator::Implicit,
            PlanarIntegratorSpec::Automatic => PlanarIntegrator::Automatic,
        };
        glue(scene, &rigid, &bodies, (&physics, &mut coupling))?;
        let mut sim = Self {
            physics,
            bodies,
            coupling,
            soft,
            rigid,
            gravity: DVec2::new(gx, gy),
            probes: Vec::new(),
        };
        sim.probes = scene
            .probe
            .iter()
            .map(|p| PlanarProbe::new(p, &sim))
            .collect();
        Ok(sim)
    }

    /// Samples every probe at time `t` (s).
    pub fn sample_probes(&mut self, t: f64) {
        let mut probes = std::mem::take(&mut self.probes);
        for probe in &mut probes {
            probe.sample(t, self);
        }
        self.probes = probes;
    }

    /// The world now as plain data at simulated time `time` (s), in the plane z = 0; a
    /// rectangle wider or taller than `2 patch` (m) (a ground slab) is drawn cut to a square of
    /// half size `patch` about its point nearest the origin, and not framed by the camera.
    pub fn snapshot(&self, time: f64, patch: f64) -> Snapshot {
        let lift = |v: &DVec2| DVec3::new(v.x, v.y, 0.0);
        let soft_bodies = (self.soft.iter().zip(&self.bodies))
            .map(|(entry, body)| SoftBodySnapshot {
                name: entry.name.clone(),
                material: entry.label.clone(),
                rest_positions: entry.start.iter().map(lift).collect(),
                positions: body.positions().iter().map(lift).collect(),
                velocities: body.velocities().iter().map(lift).collect(),
                cells: Cells::Triangles(drawn_triangles(body)),
                surface: drawn_triangles(body),
                cauchy_stress: drawn_stresses(body),
            })
            .collect();
        let rigid_bodies = (self.rigid.iter())
            .filter_map(|entry| {
                let body = self.physics.bodies.get(entry.handle)?;
                let angle = f64::from(body.rotation().angle());
                let centre = body.translation().as_dvec2();
                let (sin, cos) = angle.sin_cos();
                let (outline, has_patch) = drawn_outline(entry.shape, centre, (sin, cos), patch);
                let placed = outline.iter().map(|p| {
                    let q = DVec2::new(cos * p.x - sin * p.y, sin * p.x + cos * p.y) + centre;
                    DVec3::new(q.x, q.y, 0.0)
                });
                let triangles = (1..outline.len() as u32 - 1)
                    .map(|k| [0, k, k + 1])
                    .collect();
                Some(RigidBodySnapshot {
                    name: entry.name.clone(),
                    vertices: placed.collect(),
                    triangles,
                    has_patch,
                })
            })
            .collect();
        Snapshot {
            time,
            soft_bodies,
            rigid_bodies,
        }
    }
}

/// The triangles `body` is drawn and written as: its mesh's, or each 6-node triangle's four
/// corner and mid-edge sub-triangles (nodes ordered corners then the mid-edge nodes of edges
/// 01, 12, 20).
fn drawn_triangles(body: &PlanarBody) -> Vec<[u32; 3]> {
    if !body.is_quadratic() {
        return body.mesh().triangles().to_vec();
    }
    let (_, elements, _) = body.mesh().quadratic_nodes();
    (elements.iter())
        .flat_map(|[a, b, c, ab, bc, ca]| {
            [
                [*a, *ab, *ca],
                [*ab, *b, *bc],
                [*ca, *bc, *c],
                [*ab, *bc, *ca],
            ]
        })
        .collect()
}

/// The Cauchy stress (Pa) of each triangle of [`drawn_triangles`]: its element's.
fn drawn_stresses(body: &PlanarBody) -> Vec<rapier_fvm::glamx::DMat3> {
    let per_element = body.cauchy_stresses();
    if !body.is_quadratic() {
        return per_element;
    }
    per_element.into_iter().flat_map(|s| [s; 4]).collect()
}

/// Glues the nodes each soft body's `attach` entries select to their rigid bodies.
fn glue(
    scene: &PlanarScene,
    rigid: &[PlanarRigidEntry],
    bodies: &[PlanarBody],
    (physics, coupling): (&PhysicsWorld, &mut PlanarCoupling),
) -> Result<(), SceneError> {
    for (i, (spec, body)) in scene.soft_body.iter().zip(bodies).enumerate() {
        for (k, glue) in spec.attach.iter().enumerate() {
            let key = format!("soft_body[{i}].attach[{k}]");
            let region = PlanarBoxSpec {
                min: glue.min,
                max: glue.max,
            };
            let nodes = nodes_in(body.rest_positions(), |p| region.contains(p));
            if nodes.is_empty() {
                return Err(scene.source.error(&key, "it selects no node of the body"));
            }
            // The scene's check has made sure the rigid body exists.
            let Some(target) = rigid.iter().find(|r| r.name == glue.rigid) else {
                continue;
            };
            coupling
                .glue(physics, bodies, (i, &nodes), target.handle)
                .map_err(|e| scene.source.error(&key, e.to_string()))?;
        }
    }
    Ok(())
}

/// The soft body of `spec`, placed and moving as it says, or an error (the library's, or a pin
/// box selecting no node) with the key it is about (`.mesh`, `.material`, `.pinned[i]`,
/// `.damping` or `.volumetric`).
fn soft_body(spec: &PlanarSoftBodySpec) -> Result<PlanarBody, (String, String)> {
    let at = |key: &'static str| move |e: rapier_fvm::Error| (key.to_owned(), e.to_string());
    let mesh = mesh(spec).map_err(at(".mesh"))?;
    let material = spec.material.material().map_err(at(".material"))?;
    // The body's nodes in its order: the mesh's, then the mid-edge nodes of quadratic triangles.
    let nodes = match spec.elements {
        PlanarElementsSpec::Linear => mesh.rest_positions().to_vec(),
        PlanarElementsSpec::Quadratic => mesh.quadratic_nodes().0,
    };
    let mut pinned = Vec::new();
    for (i, region) in spec.pinned.iter().enumerate() {
        let selected = nodes_in(&nodes, |p| region.contains(p));
        if selected.is_empty() {
            let message = "it selects no node of the body (its box is in mesh coordinates, \
                           before `translation`)";
            return Err((format!(".pinned[{i}]"), message.to_owned()));
        }
        pinned.extend(selected);
    }
    let mut builder = PlanarBodyBuilder::new(mesh, material)
        .plane(match spec.plane {
            PlaneSpec::Stress => PlaneModel::PlaneStress,
            PlaneSpec::Strain => PlaneModel::PlaneStrain,
        })
        .thickness(spec.thickness)
        .volumetric(spec.volumetric.treatment())
        .pinned_nodes(pinned);
    if spec.elements == PlanarElementsSpec::Quadratic {
        builder = builder.quadratic();
    }
    if let Some(damping) = &spec.damping {
        builder = builder.damping(damping.damping(&material).map_err(at(".damping"))?);
    }
    // The builder refuses only the averaged volumetric terms it cannot take.
    let mut body = builder.build().map_err(at(".volumetric"))?;
    let offset = DVec2::from_array(spec.translation);
    let velocity = DVec2::from_array(spec.velocity);
    for x in body.positions_mut() {
        *x += offset;
    }
    let pinned: Vec<[bool; 2]> = body.pinned().to_vec();
    for (v, held) in body.velocities_mut().iter_mut().zip(pinned) {
        if !held[0] && !held[1] {
            *v = velocity;
        }
    }
    Ok(body)
}

/// The indices of the `positions` (m) that `inside` accepts.
fn nodes_in(positions: &[DVec2], inside: impl Fn([f64; 2]) -> bool) -> Vec<usize> {
    (positions.iter().enumerate())
        .filter(|(_, p)| inside(p.to_array()))
        .map(|(i, _)| i)
        .collect()
}

/// The triangle mesh of `spec`, in its own coordinates.
fn mesh(spec: &PlanarSoftBodySpec) -> Result<TriangleMesh, rapier_fvm::Error> {
    match &spec.mesh {
        PlanarMeshSpec::Rectangle {
            size: [w, h],
            cells,
        } => TriangleMesh::rectangle(DVec2::new(*w, *h), *cells),
        PlanarMeshSpec::Disk { radius, rings } => TriangleMesh::disk(*radius, *rings),
        PlanarMeshSpec::Polygon {
            outline,
            edge_length,
        } => {
            let outline: Vec<DVec2> = outline.iter().map(|&p| DVec2::from_array(p)).collect();
            TriangleMesh::polygon(&outline, *edge_length)
        }
    }
}

/// Inserts the rigid body of `spec` with its collider into `physics`.
fn insert_rigid(physics: &mut PhysicsWorld, spec: &PlanarRigidBodySpec) -> PlanarRigidEntry {
    let builder = match spec.kind {
        PlanarRigidKind::Fixed => RigidBodyBuilder::fixed(),
        PlanarRigidKind::Dynamic => RigidBodyBuilder::dynamic(),
    };
    let [x, y] = spec.translation.map(|v| v as f32);
    let [vx, vy] = spec.velocity.map(|v| v as f32);
    let body = builder
        .translation([x, y].into())
        .rotation(spec.rotation as f32)
        .linvel([vx, vy].into())
        .angvel(spec.angular_velocity as f32);
    let collider = match spec.shape {
        PlanarShapeSpec::Cuboid {
            half_extents: [a, b],
        } => ColliderBuilder::cuboid(a as f32, b as f32),
        PlanarShapeSpec::Ball { radius } => ColliderBuilder::ball(radius as f32),
    }
    .density(spec.density as f32);
    let handle = physics.bodies.insert(body);
    let collider =
        physics
            .colliders
            .insert_with_parent(collider.build(), handle, &mut physics.bodies);
    PlanarRigidEntry {
        name: spec.name.clone(),
        handle,
        collider,
        shape: spec.shape,
    }
}

/// The outline drawn of `shape` (m, about its centre, counter-clockwise) placed at `centre` (m)
/// and turned by the angle of sine and cosine `turn`: a disk as a polygon, a rectangle cut to a
/// square of half size `patch` (m) about its point nearest the origin; and whether it was cut.
fn drawn_outline(
    shape: PlanarShapeSpec,
    centre: DVec2,
    (sin, cos): (f64, f64),
    patch: f64,
) -> (Vec<DVec2>, bool) {
    let half = match shape {
        PlanarShapeSpec::Cuboid { half_extents } => DVec2::from_array(half_extents),
        PlanarShapeSpec::Ball { radius } => {
            let polygon = (0..BALL_SEGMENTS).map(|k| {
                let angle = std::f64::consts::TAU * k as f64 / BALL_SEGMENTS as f64;
                DVec2::new(angle.cos(), angle.sin()) * radius
            });
            return (polygon.collect(), false);
        }
    };
    // The origin in the rectangle's frame, then the rectangle's point nearest it.
    let origin = DVec2::new(
        -cos * centre.x - sin * centre.y,
        sin * centre.x - cos * centre.y,
    );
    let nearest = origin.clamp(-half, half);
    let lo = (nearest - DVec2::splat(patch)).max(-half);
    let hi = (nearest + DVec2::splat(patch)).min(half);
    let cut = lo != -half || hi != half;
    let corners = vec![lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    (corners, cut)
}
