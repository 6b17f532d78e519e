//! Triangle meshes of rapier collider shapes, in world space, through parry's `to_trimesh`.
//! Unbounded shapes (half-spaces) and cuboids larger than a given patch size are drawn as finite
//! square patches, so a ground does not swallow the picture.

use rapier_fvm::glamx::DVec3;
use rapier3d::math::{Pose, Vector};
use rapier3d::parry::shape::{Cuboid, Shape, TypedShape};

/// Subdivisions around curved shapes (balls, capsules, cylinders, cones).
const AROUND: u32 = 24;
/// Subdivisions from pole to pole of balls and capsules.
const POLE_TO_POLE: u32 = 12;

/// A world-space triangle mesh of one collider.
#[derive(Debug, Default)]
pub(crate) struct ShapeMesh {
    /// Vertices (m).
    pub(crate) vertices: Vec<DVec3>,
    /// Triangles (vertex indices).
    pub(crate) triangles: Vec<[u32; 3]>,
    /// Whether part of it is a finite patch of an unbounded or huge shape.
    pub(crate) is_patch: bool,
}

impl ShapeMesh {
    /// Adds a local-space mesh placed by `pose`.
    fn push(&mut self, pose: &Pose, (vertices, triangles): (Vec<Vector>, Vec<[u32; 3]>)) {
        let offset = self.vertices.len() as u32;
        self.vertices.extend(
            vertices
                .into_iter()
                .map(|v| pose.transform_point(v).as_dvec3()),
        );
        self.triangles
            .extend(triangles.into_iter().map(|t| t.map(|i| i + offset)));
    }
}

/// The triangles of `shape` placed at `pose`, with unbounded or huge parts cut to square patches
/// of half size `patch_half_size` (m) around the shape's origin. Segments, polylines and custom
/// shapes have no surface and give no triangles; rounded shapes are drawn without their rounding.
pub(crate) fn collider_triangles(
    shape: &dyn Shape,
    pose: &Pose,
    patch_half_size: f64,
) -> ShapeMesh {
    let mut mesh = ShapeMesh::default();
    append(&mut mesh, shape, pose, patch_half_size as f32);
    mesh
}

fn append(mesh: &mut ShapeMesh, shape: &dyn Shape, pose: &Pose, patch: f32) {
    let local = match shape.as_typed_shape() {
        TypedShape::Ball(s) => s.to_trimesh(AROUND, POLE_TO_POLE),
        TypedShape::Cuboid(s) => cuboid(mesh, s, patch),
        TypedShape::RoundCuboid(s) => cuboid(mesh, &s.inner_shape, patch),
        TypedShape::Capsule(s) => s.to_trimesh(AROUND, POLE_TO_POLE),
        TypedShape::Cylinder(s) => s.to_trimesh(AROUND),
        TypedShape::RoundCylinder(s) => s.inner_shape.to_trimesh(AROUND),
        TypedShape::Cone(s) => s.to_trimesh(AROUND),
        TypedShape::RoundCone(s) => s.inner_shape.to_trimesh(AROUND),
        TypedShape::ConvexPolyhedron(s) => s.to_trimesh(),
        TypedShape::RoundConvexPolyhedron(s) => s.inner_shape.to_trimesh(),
        TypedShape::TriMesh(s) => (s.vertices().to_vec(), s.indices().to_vec()),
        TypedShape::HeightField(s) => s.to_trimesh(),
        TypedShape::Voxels(s) => s.to_trimesh(),
        TypedShape::Triangle(s) => (vec![s.a, s.b, s.c], vec![[0, 1, 2]]),
        TypedShape::RoundTriangle(s) => {
            let t = &s.inner_shape;
            (vec![t.a, t.b, t.c], vec![[0, 1, 2]])
        }
        TypedShape::HalfSpace(s) => {
            mesh.is_patch = true;
            half_space_patch(s.normal, patch)
        }
        TypedShape::Compound(s) => {
            for (child_pose, child) in s.shapes() {
                append(mesh, child.as_ref(), &(*pose * *child_pose), patch);
            }
            return;
        }
        _ => return,
    };
    mesh.push(pose, local);
}

/// A cuboid, its half extents cut to `patch` (m).
fn cuboid(mesh: &mut ShapeMesh, s: &Cuboid, patch: f32) -> (Vec<Vector>, Vec<[u32; 3]>) {
    let clipped = s.half_extents.min(Vector::splat(patch));
    mesh.is_patch |= clipped != s.half_extents;
    Cuboid::new(clipped).to_trimesh()
}

/// A square of half size `patch` (m) in the plane through the origin with unit normal `normal`,
/// its triangles facing along `normal`.
fn half_space_patch(normal: Vector, patch: f32) -> (Vec<Vector>, Vec<[u32; 3]>) {
    let (u, v) = normal.any_orthonormal_pair();
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .map(|(a, b)| (u * a + v * b) * patch)
        .to_vec();
    let mut triangles = vec![[0, 1, 2], [0, 2, 3]];
    let [a, b, c] = triangles[0].map(|i| corners[i as usize]);
    if (b - a).cross(c - a).dot(normal) < 0.0 {
        for t in &mut triangles {
            t.swap(1, 2);
        }
    }
    (corners, triangles)
}
