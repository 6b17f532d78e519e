//! Follower loads, which turn with the body: a pressure on triangles and a cable through a path
//! of nodes. Their forces, potentials and the potentials' Hessians (the Newton tangent):
//!
//! - pressure `p` on a triangle `(a, b, c)`: each corner carries `f = -p (x_b − x_a) × (x_c −
//!   x_a) / 6` (N); the potential `U = p V`, `V = y_a · (y_b × y_c) / 6` with `y = x − o`, has
//!   `∂²U/∂x_a∂x_b = -(p/6) [y_c]ₓ` and the cyclic blocks (`[v]ₓ` the cross-product matrix,
//!   `[v]ₓ w = v × w`), zero diagonal blocks; summed over a closed surface they do not depend on
//!   `o`, which is taken at the triangles' centre for round-off;
//! - cable of tension `T` through `x_0 … x_k`: `U = T Σ |d_i|`, `d_i = x_{i+1} − x_i`, each
//!   segment's Hessian `±T (I − d̂ d̂ᵀ) / |d|` on its two nodes.

use crate::assembly::Stiffness;
use crate::body::DeformableBody;
use rapier3d::glamx::{DMat3, DVec3};

/// Adds the forces (N) of a pressure `pressure` (Pa) on `triangles` at the positions `x` (m).
pub(super) fn add_pressure_forces(
    triangles: &[[u32; 3]],
    pressure: f64,
    x: &[DVec3],
    forces: &mut [DVec3],
) {
    for &[a, b, c] in triangles {
        let [xa, xb, xc] = [a, b, c].map(|n| x[n as usize]);
        let corner = (xb - xa).cross(xc - xa) * (-pressure / 6.0);
        for n in [a, b, c] {
            forces[n as usize] += corner;
        }
    }
}

/// Adds minus the gradient (N) of the potential `p V` of a pressure `pressure` (Pa) on
/// `triangles` at the positions `x` (m), the cone measured from `origin` (m): corner `a` of a
/// triangle carries `-p (y_b × y_c) / 6`, `y = x − origin`.
pub(super) fn add_cone_forces(
    triangles: &[[u32; 3]],
    pressure: f64,
    x: &[DVec3],
    origin: DVec3,
    forces: &mut [DVec3],
) {
    let scale = -pressure / 6.0;
    for &[a, b, c] in triangles {
        let [ya, yb, yc] = [a, b, c].map(|n| x[n as usize] - origin);
        forces[a as usize] += yb.cross(yc) * scale;
        forces[b as usize] += yc.cross(ya) * scale;
        forces[c as usize] += ya.cross(yb) * scale;
    }
}

/// The mean position (m) of the corners of `triangles` at the positions `x` (m), counted once
/// per triangle corner.
pub(super) fn centre(triangles: &[[u32; 3]], x: &[DVec3]) -> DVec3 {
    let sum: DVec3 = triangles.iter().flatten().map(|&n| x[n as usize]).sum();
    sum / (3 * triangles.len()).max(1) as f64
}

/// The signed volume (m³) of the cone the triangles span from `origin` (m) at the positions `x`
/// (m): positive on the side their normals point to.
pub(super) fn cone_volume(triangles: &[[u32; 3]], x: &[DVec3], origin: DVec3) -> f64 {
    triangles
        .iter()
        .map(|&[a, b, c]| {
            let [ya, yb, yc] = [a, b, c].map(|n| x[n as usize] - origin);
            ya.dot(yb.cross(yc))
        })
        .sum::<f64>()
        / 6.0
}

/// Whether `triangles` make a closed, consistently oriented surface: every directed edge once,
/// its reverse once.
pub(super) fn is_closed(triangles: &[[u32; 3]]) -> bool {
    let mut edges = std::collections::HashMap::new();
    for &[a, b, c] in triangles {
        for edge in [(a, b), (b, c), (c, a)] {
            *edges.entry(edge).or_insert(0u32) += 1;
        }
    }
    !edges.is_empty()
        && edges
            .iter()
            .all(|(&(a, b), &count)| count == 1 && edges.get(&(b, a)) == Some(&1))
}

/// Adds the forces (N) of a cable of tension `tension` (N) through `path` at the positions `x`
/// (m).
pub(super) fn add_cable_forces(path: &[u32], tension: f64, x: &[DVec3], forces: &mut [DVec3]) {
    for segment in path.windows(2) {
        let (i, j) = (segment[0] as usize, segment[1] as usize);
        let pull = (x[j] - x[i]).normalize_or_zero() * tension;
        forces[i] += pull;
        forces[j] -= pull;
    }
}

/// The length (m) of the polyline through `path` at the positions `x` (m).
pub(super) fn path_length(path: &[u32], x: &[DVec3]) -> f64 {
    path.windows(2)
        .map(|s| x[s[1] as usize].distance(x[s[0] as usize]))
        .sum()
}

/// The cross-product matrix `[v]ₓ`, `[v]ₓ w = v × w`.
fn cross_matrix(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}

/// Adds the Hessians (N/m) of the potentials of `body`'s follower loads at its current
/// positions to `stiffness` (see the module documentation), skipping pinned nodes. A chamber
/// adds its pressure's part (its liquid's rank-one part is taken in by the Newton direction,
/// see `super::chamber`), but not to a tangent that is `projected` to be positive definite: the
/// pressure's blocks are indefinite, and a liquid pumped beyond what the cavity holds pushes
/// with a pressure of the order of its bulk modulus until the walls give way.
pub(crate) fn add_follower_tangents(
    body: &DeformableBody,
    stiffness: &mut Stiffness,
    projected: bool,
) {
    let (x, pinned) = (body.positions(), &body.pinned);
    for load in body.loads() {
        match load {
            super::Load::Chamber { .. } if projected => {}
            super::Load::Pressure { triangles, .. } | super::Load::Chamber { triangles, .. } => {
                let pressure = load.pressure_at(x).unwrap_or(0.0);
                let origin = centre(triangles, x);
                for &[a, b, c] in triangles {
                    let [ya, yb, yc] = [a, b, c].map(|n| x[n as usize] - origin);
                    let scale = -pressure / 6.0;
                    for (p, q, opposite) in [(a, b, yc), (b, c, ya), (c, a, yb)] {
                        let block = cross_matrix(opposite) * scale;
                        stiffness.add_pair(p as usize, q as usize, &block, pinned);
                    }
                }
            }
            super::Load::Cable { path, tension } => {
                for segment in path.windows(2) {
                    let (i, j) = (segment[0] as usize, segment[1] as usize);
                    let d = x[j] - x[i];
                    let length = d.length();
                    if length == 0.0 {
                        continue;
                    }
                    let unit = d / length;
                    let block = (DMat3::IDENTITY
                        - DMat3::from_cols(unit * unit.x, unit * unit.y, unit * unit.z))
                        * (tension / length);
                    stiffness.add_pair(i, i, &block, pinned);
                    stiffness.add_pair(j, j, &block, pinned);
                    stiffness.add_pair(i, j, &(-block), pinned);
                }
            }
            super::Load::Traction { .. } | super::Load::BodyForce { .. } => {}
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use crate::assembly::{Stiffness, perturb_positions};
    use crate::body::{DeformableBody, DeformableBodyBuilder};
    use crate::load::Load;
    use crate::material::{Material, MaterialModel};
    use crate::mesh;
    use rapier3d::glamx::DVec3;

    /// A free 0.2 m cube, deformed, under a pressure of 1 kPa on its whole surface (a closed
    /// surface) and a cable of 50 N through four of its nodes.
    fn loaded_cube() -> DeformableBody {
        let mesh = mesh::cuboid(DVec3::splat(0.1), [2, 2, 2]).unwrap();
        let surface = mesh.surface_triangles();
        let material = Material::new(MaterialModel::Linear, 1e6, 0.3, 1000.0).unwrap();
        let mut body = DeformableBodyBuilder::new(mesh, material).build().unwrap();
        perturb_positions(&mut body, 7, 0.01);
        body.add_load(Load::Pressure {
            triangles: surface,
            pressure: 1e3,
        })
        .unwrap();
        body.add_load(Load::Cable {
            path: vec![0, 13, 26, 5],
            tension: 50.0,
        })
        .unwrap();
        body
    }

    fn follower_forces(body: &DeformableBody) -> Vec<DVec3> {
        let mut forces = vec![DVec3::ZERO; body.node_count()];
        body.add_follower_forces(&mut forces);
        forces
    }

    /// A fixed vector per node (of order one), zero on pinned nodes: a direction of motion or
    /// an out-of-balance force for the tests.
    pub(in crate::load) fn fixed_direction(body: &DeformableBody) -> Vec<DVec3> {
        (0..body.node_count())
            .map(|i| {
                if body.pinned[i] {
                    DVec3::ZERO
                } else {
                    DVec3::new((i % 3) as f64 - 1.0, (i % 5) as f64 * 0.5 - 1.0, 0.7)
                }
            })
            .collect()
    }

    /// Checks by central differences of 1e-7 m along a fixed direction (zero on pinned nodes),
    /// on a body of about 0.1 m (truncation about 1e-12, round-off about 1e-9 relative), that
    /// the follower loads' forces are minus the gradient of their potential (to 1e-7 relative)
    /// and that their tangent, the assembled Hessians plus `unassembled(body, d)` (N per node),
    /// is minus the gradient of the forces at the free nodes (to 1e-6 of the largest `K d`).
    pub(in crate::load) fn assert_forces_and_tangent_derive_from_the_potential(
        body: &mut DeformableBody,
        unassembled: impl Fn(&DeformableBody, &[DVec3]) -> Vec<DVec3>,
    ) {
        let n = body.node_count();
        let direction = fixed_direction(body);
        let start = body.positions().to_vec();
        let origins = body.cone_origins();
        let h = 1e-7;
        let at = |body: &mut DeformableBody, step: f64| {
            for ((x, x0), d) in body.positions_mut().iter_mut().zip(&start).zip(&direction) {
                *x = *x0 + *d * step;
            }
            (
                body.follower_potential(&origins, &start),
                follower_forces(body),
            )
        };
        let (_, forces) = at(body, 0.0);
        let (u_plus, f_plus) = at(body, h);
        let (u_minus, f_minus) = at(body, -h);
        at(body, 0.0);
        let slope = (u_plus - u_minus) / (2.0 * h);
        let work: f64 = forces.iter().zip(&direction).map(|(f, d)| f.dot(*d)).sum();
        assert!(
            (slope + work).abs() <= 1e-7 * work.abs(),
            "dU/ds {slope} vs -f·d {}",
            -work
        );
        let mut stiffness = Stiffness::new(body);
        stiffness.values.fill(0.0);
        super::add_follower_tangents(body, &mut stiffness, false);
        let mut k_d = stiffness.multiply(&direction);
        for (k_d, extra) in k_d.iter_mut().zip(unassembled(body, &direction)) {
            *k_d += extra;
        }
        let scale = k_d.iter().map(|v| v.length()).fold(0.0, f64::max);
        for node in (0..n).filter(|&node| !body.pinned[node]) {
            let difference = -(f_plus[node] - f_minus[node]) / (2.0 * h);
            assert!(
                (difference - k_d[node]).length() <= 1e-6 * scale,
                "node {node}: K d {} vs -df/ds {difference}",
                k_d[node]
            );
        }
    }

    /// The pressure's and the cable's forces and tangents derive from their potentials on the
    /// free cube (see [`assert_forces_and_tangent_derive_from_the_potential`]).
    #[test]
    fn forces_and_tangent_derive_from_the_potential_on_a_closed_surface() {
        let mut body = loaded_cube();
        assert_forces_and_tangent_derive_from_the_potential(&mut body, |body, _| {
            vec![DVec3::ZERO; body.node_count()]
        });
    }

    /// A pressure on a closed surface and a cable anchored in the body are internal: no net
    /// force or torque (about the origin) to round-off, 1e-12 of the largest nodal force (and
    /// its moment arm of 0.1 m).
    #[test]
    fn closed_pressure_and_cable_exert_no_net_force_or_torque() {
        let body = loaded_cube();
        let forces = follower_forces(&body);
        let largest = forces.iter().map(|f| f.length()).fold(0.0, f64::max);
        let net: DVec3 = forces.iter().sum();
        let torque: DVec3 = (body.positions().iter().zip(&forces))
            .map(|(x, f)| x.cross(*f))
            .sum();
        assert!(net.length() <= 1e-12 * largest, "{net}");
        assert!(torque.length() <= 1e-12 * largest * 0.1, "{torque}");
    }

    /// The volume a closed surface encloses is the mesh's volume (to 1e-12), with the sign of a
    /// cavity seen from outside it: the outer surface's triangles point away from the volume.
    #[test]
    fn enclosed_volume_of_a_closed_surface_is_the_mesh_volume() {
        let mesh = mesh::cuboid(DVec3::new(0.1, 0.2, 0.3), [2, 3, 4]).unwrap();
        let load = Load::Pressure {
            triangles: mesh.surface_triangles(),
            pressure: 1.0,
        };
        let volume = load.enclosed_volume(mesh.positions()).unwrap();
        assert!(
            (volume + mesh.volume()).abs() <= 1e-12 * mesh.volume(),
            "{volume}"
        );
    }
}
