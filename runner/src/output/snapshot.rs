//! What the writers draw: a plain copy of the world at one saved frame. The runner fills one per
//! frame; the writers read nothing else.

use super::rigid_mesh::collider_triangles;
use rapier_fvm::body::DeformableBody;
use rapier_fvm::glamx::{DMat3, DVec3};
use rapier3d::dynamics::RigidBodyHandle;
use rapier3d::pipeline::PhysicsWorld;

/// The world at one saved frame.
#[derive(Debug, Clone, Default)]
pub struct Snapshot {
    /// Simulated time (s).
    pub time: f64,
    /// The soft bodies.
    pub soft_bodies: Vec<SoftBodySnapshot>,
    /// The rigid bodies and free colliders, as triangle meshes.
    pub rigid_bodies: Vec<RigidBodySnapshot>,
}

/// The cells of a soft body: tetrahedra in 3D, triangles in the plane (z = 0).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Cells {
    /// Tetrahedra (node indices).
    Tetrahedra(Vec<[u32; 4]>),
    /// Triangles (node indices) of a 2D body.
    Triangles(Vec<[u32; 3]>),
}

impl Cells {
    /// How many cells there are.
    pub fn len(&self) -> usize {
        match self {
            Self::Tetrahedra(cells) => cells.len(),
            Self::Triangles(cells) => cells.len(),
        }
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Each cell's nodes, in order.
    pub fn nodes(&self) -> Box<dyn Iterator<Item = &[u32]> + '_> {
        match self {
            Self::Tetrahedra(cells) => Box::new(cells.iter().map(|c| &c[..])),
            Self::Triangles(cells) => Box::new(cells.iter().map(|c| &c[..])),
        }
    }
}

/// One soft body at one frame. Node and cell order are the body's mesh order.
#[derive(Debug, Clone)]
pub struct SoftBodySnapshot {
    /// The body's name (file names are made from it).
    pub name: String,
    /// A label of its material, e.g. `"rubber"`: bodies with the same label get the same colour.
    pub material: String,
    /// Reference positions (m): the undeformed body as placed in the world, usually its world
    /// positions before the first step. Displacements are measured from them.
    pub rest_positions: Vec<DVec3>,
    /// World positions of the nodes (m).
    pub positions: Vec<DVec3>,
    /// Node velocities (m/s).
    pub velocities: Vec<DVec3>,
    /// The cells.
    pub cells: Cells,
    /// The triangles drawn (node indices): for a 3D body its boundary, normals
    /// `(b - a) × (c - a)` pointing out of the body; for a 2D body its triangles.
    pub surface: Vec<[u32; 3]>,
    /// Cauchy stress per cell (Pa), world axes: see [`DeformableBody::cauchy_stresses`] (and
    /// `PlanarBody::cauchy_stresses`, with `σ₃₃` across the plane).
    pub cauchy_stress: Vec<DMat3>,
}

/// One rigid body (all its colliders) or one collider without a body, at one frame.
#[derive(Debug, Clone)]
pub struct RigidBodySnapshot {
    /// The body's name.
    pub name: String,
    /// World positions of the mesh vertices (m).
    pub vertices: Vec<DVec3>,
    /// Triangles (vertex indices), normals pointing outwards.
    pub triangles: Vec<[u32; 3]>,
    /// Whether part of the mesh is a finite patch standing for an unbounded or very large shape
    /// (a ground half-space or a huge cuboid): drawn, but not framed by the camera.
    pub has_patch: bool,
}

impl SoftBodySnapshot {
    /// A copy of `body`'s state named `name`, with material label `material` and reference
    /// positions `rest_positions` (m, one per node).
    ///
    /// # Panics
    /// If `rest_positions` does not have one position per node of `body`.
    pub fn capture(
        name: impl Into<String>,
        material: impl Into<String>,
        body: &DeformableBody,
        rest_positions: &[DVec3],
    ) -> Self {
        assert_eq!(
            rest_positions.len(),
            body.node_count(),
            "one reference position per node"
        );
        // A body carrying an embedded mesh is shown by that mesh, which moves with the nodes.
        if let Some(embedding) = body.embedding() {
            return Self {
                name: name.into(),
                material: material.into(),
                rest_positions: embedding.positions(rest_positions),
                positions: embedding.positions(body.positions()),
                velocities: embedding.positions(body.velocities()),
                cells: Cells::Tetrahedra(embedding.mesh().tets().to_vec()),
                surface: embedding.surface_triangles().to_vec(),
                cauchy_stress: body.embedded_cauchy_stresses().unwrap_or_default(),
            };
        }
        Self {
            name: name.into(),
            material: material.into(),
            rest_positions: rest_positions.to_vec(),
            positions: body.positions().to_vec(),
            velocities: body.velocities().to_vec(),
            cells: Cells::Tetrahedra(body.mesh().tets().to_vec()),
            surface: body.mesh().surface_triangles(),
            cauchy_stress: body.cauchy_stresses(),
        }
    }

    /// Node displacements `x - X` (m) from the reference positions.
    pub fn displacements(&self) -> Vec<DVec3> {
        self.positions
            .iter()
            .zip(&self.rest_positions)
            .map(|(x, p)| *x - *p)
            .collect()
    }

    /// Von Mises equivalent stress per cell (Pa).
    pub fn von_mises(&self) -> Vec<f64> {
        self.cauchy_stress
            .iter()
            .map(DeformableBody::von_mises)
            .collect()
    }

    /// Von Mises stress per node (Pa): the mean over the node's cells, for smooth colouring.
    pub fn nodal_von_mises(&self) -> Vec<f64> {
        let mut sum = vec![0.0; self.positions.len()];
        let mut count = vec![0u32; self.positions.len()];
        for (cell, value) in self.cells.nodes().zip(self.von_mises()) {
            for &n in cell {
                sum[n as usize] += value;
                count[n as usize] += 1;
            }
        }
        sum.iter()
            .zip(count)
            .map(|(s, c)| if c == 0 { 0.0 } else { s / f64::from(c) })
            .collect()
    }
}

impl RigidBodySnapshot {
    /// The colliders of rigid body `handle` in `physics`, named `name`, as one world-space mesh.
    /// Unbounded shapes and cuboids larger than `patch_half_size` (m) become square patches of
    /// that half size around their origin. `None` if the body does not exist.
    pub fn of_body(
        name: impl Into<String>,
        physics: &PhysicsWorld,
        handle: RigidBodyHandle,
        patch_half_size: f64,
    ) -> Option<Self> {
        let body = physics.bodies.get(handle)?;
        let mut snapshot = Self::empty(name.into());
        for &collider in body.colliders() {
            if let Some(collider) = physics.colliders.get(collider) {
                snapshot.append(collider, patch_half_size);
            }
        }
        Some(snapshot)
    }

    /// Every rigid body of `physics` (named `rigid body <index>`) and every collider attached to
    /// no body (named `collider <index>`), meshed as in [`RigidBodySnapshot::of_body`].
    pub fn all_of(physics: &PhysicsWorld, patch_half_size: f64) -> Vec<Self> {
        let bodies = physics.bodies.iter().filter_map(|(handle, _)| {
            let name = format!("rigid body {}", handle.into_raw_parts().0);
            Self::of_body(name, physics, handle, patch_half_size)
        });
        let free = physics
            .colliders
            .iter()
            .filter(|(_, collider)| collider.parent().is_none())
            .map(|(handle, collider)| {
                let mut snapshot = Self::empty(format!("collider {}", handle.into_raw_parts().0));
                snapshot.append(collider, patch_half_size);
                snapshot
            });
        bodies.chain(free).collect()
    }

    fn empty(name: String) -> Self {
        Self {
            name,
            vertices: Vec::new(),
            triangles: Vec::new(),
            has_patch: false,
        }
    }

    /// Adds `collider`'s world-space triangles.
    fn append(&mut self, collider: &rapier3d::geometry::Collider, patch_half_size: f64) {
        let mesh = collider_triangles(collider.shape(), collider.position(), patch_half_size);
        let offset = self.vertices.len() as u32;
        self.vertices.extend(mesh.vertices);
        self.triangles
            .extend(mesh.triangles.iter().map(|t| t.map(|i| i + offset)));
        self.has_patch |= mesh.is_patch;
    }
}

impl Snapshot {
    /// The box `(min, max)` (m) around every soft body and every rigid body without a patch, or
    /// `None` if there is nothing to frame.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let soft = self.soft_bodies.iter().flat_map(|b| b.positions.iter());
        let rigid = self
            .rigid_bodies
            .iter()
            .filter(|b| !b.has_patch)
            .flat_map(|b| b.vertices.iter());
        soft.chain(rigid).fold(None, |bounds, &p| match bounds {
            None => Some((p, p)),
            Some((lo, hi)) => Some((lo.min(p), hi.max(p))),
        })
    }
}
