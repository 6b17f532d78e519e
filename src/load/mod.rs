//! Loads applied to a deformable body besides gravity, each a force field on its nodes that the
//! caller sets and changes between frames as a controller does:
//!
//! - **traction** `t` (Pa) on boundary triangles, a dead load on their rest area `A₀`: each
//!   corner carries `t A₀ / 3` (N), whatever the body does;
//! - **body force** `b` (N/m³), such as a magnetic or an inertial field: node `n` carries
//!   `b V_n` with `V_n = m_n / ρ` its lumped control volume (m³);
//! - **pressure** `p` (Pa), a follower load on boundary triangles, pushing against the body along
//!   their current normals: each corner carries `-p a / 3` with `a = ½ (x_b − x_a) × (x_c − x_a)`
//!   the triangle's area vector (m², out of the body). On the closed inner surface of a cavity it
//!   is the cavity's pressure (a pneumatic actuator), and [`Load::enclosed_volume`] the cavity's
//!   volume ([`statics::inflate_to_volume`](crate::statics::inflate_to_volume) finds the
//!   pressure that fills it to a given volume at equilibrium);
//! - **cable** of tension `T` (N) running through a path of nodes (eyelets), anchored at both
//!   ends in the body: node `i` is pulled toward its neighbours on the path,
//!   `T (ê_{i→i−1} + ê_{i→i+1})`, as a tendon pulled by an actuator in the body is;
//! - **chamber**: a cavity filled with a liquid of bulk modulus `K` (Pa) that a pump holds at a
//!   volume `V*` (m³), a cavity inflated to a volume rather than a pressure: its walls carry the
//!   liquid's pressure `p = K (V* − V)/V*`, a follower pressure, with the potential
//!   `U = K (V − V*)²/(2V*)` (see [`Load::Chamber`]).
//!
//! Traction and body force are constant over a step. Pressure and cable derive from the
//! potentials `U = p V(x)`, `V = Σ (x_a − o)·((x_b − o) × (x_c − o)) / 6` over the triangles
//! (the signed volume of the cone they span from a point `o`; minus a cavity's volume), and
//! `U = T L(x)` with `L` the path's length: an implicit step and a static solve take their exact,
//! symmetric Hessians into the Newton tangent. A pressure's force is the gradient
//! of its potential wherever the surface is closed around a node; what is left, `R = f + ∇U`,
//! acts on the rim of an open surface alone (`(p/6) Σ (x_a − o) × (x_b − x_c)` over a node's
//! triangles, which vanishes around a node inside the surface) and has no potential. An
//! implicit step holds `R` at its value at the step's start, a dead load over the step, so that
//! its Newton solve descends an energy (exact on a closed surface or a pinned rim, first order
//! in the step at a free rim); a static solve takes `R` afresh at every Newton iteration and
//! meets the exact follower load at equilibrium; explicit steps use the exact force.
//! A chamber derives from its potential alike (its closed surface has no rim). Every load is
//! internal in the sense of momentum where it should be: a cavity's pressure, a chamber and a
//! cable exert no net force or torque on the body.

mod chamber;
mod follower;
mod value;

pub use chamber::WATER_BULK_MODULUS;
pub(crate) use chamber::{ChamberSolve, ChamberTerms};
pub(crate) use follower::add_follower_tangents;

use rapier3d::glamx::DVec3;

/// A load on a deformable body (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub enum Load {
    /// A dead traction (Pa) on boundary triangles' rest area.
    Traction {
        /// The triangles, node indices oriented out of the body (as
        /// [`TetMesh::surface_triangles`](crate::mesh::TetMesh::surface_triangles) gives them).
        triangles: Vec<[u32; 3]>,
        /// The traction (Pa), in the world frame.
        traction: DVec3,
    },
    /// A follower pressure (Pa) on boundary triangles, positive pushing into the body.
    Pressure {
        /// The triangles, node indices oriented out of the body.
        triangles: Vec<[u32; 3]>,
        /// The pressure (Pa).
        pressure: f64,
    },
    /// A force per unit volume (N/m³) on every node.
    BodyForce {
        /// The force density (N/m³), in the world frame.
        density: DVec3,
    },
    /// A cable of tension `tension` (N) through the nodes of `path`, in order.
    Cable {
        /// The eyelets, from one anchor to the other (at least two nodes, no node twice in a
        /// row).
        path: Vec<u32>,
        /// The tension (N), not negative: a cable pulls, it cannot push.
        tension: f64,
    },
    /// A cavity filled with a liquid of bulk modulus `K` (Pa) that a pump holds at the volume
    /// `V*` (m³), as a hydraulic actuator is driven by volume. At the cavity's volume `V` the
    /// liquid stores `U = K (V − V*)²/(2V*)` (J) and pushes on the walls with the pressure
    /// `p = K (V* − V)/V*` (Pa, [`Load::pressure_at`]), so the cavity gives way by `p/K` of its
    /// volume. Its tangent is the follower pressure's at `p` plus `(K/V*) g gᵀ` (`g = ∂V/∂x`),
    /// a rank-one term coupling every node of the walls that Newton solves take in by the
    /// Woodbury identity with the factorization of the rest: a body with a chamber is solved by
    /// factorization whatever [`LinearSolver`](crate::linear_solver::LinearSolver) says. Its
    /// value ([`Load::set`]) is the volume `V*`. Pulled beyond `V*`, the liquid pulls the walls
    /// in (a negative pressure: it is not let to boil).
    ///
    /// ```
    /// # #[cfg(feature = "import")] {
    /// use rapier_fvm::load::WATER_BULK_MODULUS;
    /// use rapier_fvm::mesh::import::{self, SurfaceOptions};
    /// use rapier_fvm::prelude::*;
    ///
    /// // gmsh's hollow sphere (radii 50 and 25 mm), its cavity filled with water.
    /// let file = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/meshes/hollow_sphere_v41.msh");
    /// let shell = import::load_raw(file, 0.001, &SurfaceOptions::default())?.into_mesh()?;
    /// let walls = shell.surface_triangles_where(|p| p.length() < 0.026);
    /// let rubber = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.45, 1100.0)?;
    /// let mut body = DeformableBodyBuilder::new(shell, rubber).build()?;
    /// let rest = Load::enclosed_volume_of(&walls, body.positions()).expect("a closed surface");
    /// let chamber = Load::Chamber { triangles: walls, volume: rest, bulk_modulus: WATER_BULK_MODULUS };
    /// let pump = body.add_load(chamber)?;
    /// // A controller pumps in 1 % more; the walls, not moved yet, feel K (V* − V)/V*.
    /// body.set_load(pump, LoadValue::Scalar(1.01 * rest))?;
    /// let pressure = body.load(pump).unwrap().pressure_at(body.positions()).unwrap();
    /// assert!((pressure / (WATER_BULK_MODULUS * 0.01 / 1.01) - 1.0).abs() < 1e-9);
    /// # }
    /// # Ok::<(), rapier_fvm::Error>(())
    /// ```
    Chamber {
        /// The cavity's walls: a closed, consistently oriented surface, node indices oriented
        /// out of the body (into the cavity).
        triangles: Vec<[u32; 3]>,
        /// The volume (m³) the pump holds the liquid at, positive: what the cavity encloses
        /// when the liquid is at zero pressure.
        volume: f64,
        /// The liquid's bulk modulus (Pa), positive ([`WATER_BULK_MODULUS`] for water).
        bulk_modulus: f64,
    },
}

/// A load's index on its body, given by
/// [`DeformableBody::add_load`](crate::body::DeformableBody::add_load).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(
    feature = "serde-serialize",
    derive(serde::Serialize, serde::Deserialize)
)]
pub struct LoadHandle(pub u32);

/// The magnitude a controller sets on a load each frame: what [`Load::set`] changes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LoadValue {
    /// A traction (Pa) or force density (N/m³), for [`Load::Traction`] and [`Load::BodyForce`].
    Vector(DVec3),
    /// A pressure (Pa), tension (N) or volume (m³), for [`Load::Pressure`], [`Load::Cable`]
    /// and [`Load::Chamber`].
    Scalar(f64),
}

impl Load {
    /// Adds the load's force (N per node) to `forces` if it is a dead load (traction, body
    /// force), at the rest positions `rest` (m) with `control_volume(n)` the rest control volume
    /// (m³) of node `n`.
    pub(crate) fn add_dead_forces(
        &self,
        rest: &[DVec3],
        control_volume: impl Fn(usize) -> f64,
        forces: &mut [DVec3],
    ) {
        match self {
            Self::Traction {
                triangles,
                traction,
            } => {
                for &[a, b, c] in triangles {
                    let [xa, xb, xc] = [a, b, c].map(|n| rest[n as usize]);
                    let area = 0.5 * (xb - xa).cross(xc - xa).length();
                    for n in [a, b, c] {
                        forces[n as usize] += *traction * (area / 3.0);
                    }
                }
            }
            Self::BodyForce { density: b } => {
                for (n, f) in forces.iter_mut().enumerate() {
                    *f += *b * control_volume(n);
                }
            }
            Self::Pressure { .. } | Self::Cable { .. } | Self::Chamber { .. } => {}
        }
    }

    /// Adds the load's force (N per node) at the positions `x` (m) to `forces` if it is a
    /// follower load (pressure, cable, chamber): the exact follower force.
    pub(crate) fn add_follower_forces(&self, x: &[DVec3], forces: &mut [DVec3]) {
        match self {
            Self::Pressure {
                triangles,
                pressure,
            } => follower::add_pressure_forces(triangles, *pressure, x, forces),
            Self::Cable { path, tension } => follower::add_cable_forces(path, *tension, x, forces),
            Self::Chamber { triangles, .. } => {
                let pressure = self.pressure_at(x).unwrap_or(0.0);
                follower::add_pressure_forces(triangles, pressure, x, forces);
            }
            Self::Traction { .. } | Self::BodyForce { .. } => {}
        }
    }

    /// The pressure (Pa) the load pushes its triangles with at the positions `x` (m): a
    /// pressure's value, a chamber's liquid's `K (V* − V)/V*`; `None` for other loads.
    pub fn pressure_at(&self, x: &[DVec3]) -> Option<f64> {
        match self {
            Self::Pressure { pressure, .. } => Some(*pressure),
            Self::Chamber {
                triangles,
                volume,
                bulk_modulus,
            } => Some(chamber::pressure(
                chamber::volume(triangles, x),
                (*volume, *bulk_modulus),
            )),
            _ => None,
        }
    }

    /// The volume (m³) the closed surface `triangles` (oriented out of the body, so into the
    /// cavity they close) encloses at the positions `x` (m): a chamber's volume at rest when `x`
    /// are the rest positions. `None` if the triangles are not a closed, consistently oriented
    /// surface; negative if they face out of what they close (a body's outer surface).
    pub fn enclosed_volume_of(triangles: &[[u32; 3]], x: &[DVec3]) -> Option<f64> {
        follower::is_closed(triangles).then(|| chamber::volume(triangles, x))
    }

    /// The point (m) a pressure's potential measures its cone from at the positions `x` (m):
    /// its triangles' centre (the world's origin for other loads, which do not use it).
    pub(crate) fn cone_origin(&self, x: &[DVec3]) -> DVec3 {
        match self {
            Self::Pressure { triangles, .. } | Self::Chamber { triangles, .. } => {
                follower::centre(triangles, x)
            }
            _ => DVec3::ZERO,
        }
    }

    /// Adds minus the gradient of the follower load's potential (N per node) at the positions
    /// `x` (m), a pressure's cone measured from `origin` (m), to `forces`: the exact follower
    /// force but on the free rim of an open surface.
    pub(crate) fn add_potential_forces(&self, origin: DVec3, x: &[DVec3], forces: &mut [DVec3]) {
        match self {
            Self::Pressure {
                triangles,
                pressure,
            } => follower::add_cone_forces(triangles, *pressure, x, origin, forces),
            Self::Cable { path, tension } => follower::add_cable_forces(path, *tension, x, forces),
            Self::Chamber { triangles, .. } => {
                // A closed surface's cone does not depend on its origin: the exact force.
                let pressure = self.pressure_at(x).unwrap_or(0.0);
                follower::add_cone_forces(triangles, pressure, x, origin, forces);
            }
            Self::Traction { .. } | Self::BodyForce { .. } => {}
        }
    }

    /// The follower load's potential `U(x) − U(x₀)` (J) between the positions `start` and `x`
    /// (m), a pressure's cone measured from `origin` (m); zero for a dead load (whose work the
    /// caller counts with gravity's).
    pub(crate) fn follower_potential(&self, origin: DVec3, start: &[DVec3], x: &[DVec3]) -> f64 {
        match self {
            Self::Pressure {
                triangles,
                pressure,
            } => {
                pressure
                    * (follower::cone_volume(triangles, x, origin)
                        - follower::cone_volume(triangles, start, origin))
            }
            Self::Cable { path, tension } => {
                tension * (follower::path_length(path, x) - follower::path_length(path, start))
            }
            Self::Chamber { .. } => self.chamber_energy(x) - self.chamber_energy(start),
            Self::Traction { .. } | Self::BodyForce { .. } => 0.0,
        }
    }

    /// The load's potential energy `U` (J) at the positions `x` (m), measured from the origin
    /// (rest positions `rest` (m) and nodal `control_volume` (m³) as for
    /// [`Load::add_dead_forces`]): `−Σ f·x` for a dead load, `p V` (the cone from the world's
    /// origin) for a pressure, `T L` for a cable, the liquid's `K (V − V*)²/(2V*)` for a
    /// chamber. Its changes are the work the load did not do.
    pub(crate) fn potential(
        &self,
        rest: &[DVec3],
        control_volume: impl Fn(usize) -> f64,
        x: &[DVec3],
    ) -> f64 {
        match self {
            Self::Traction { .. } | Self::BodyForce { .. } => {
                let mut forces = vec![DVec3::ZERO; x.len()];
                self.add_dead_forces(rest, control_volume, &mut forces);
                -forces.iter().zip(x).map(|(f, x)| f.dot(*x)).sum::<f64>()
            }
            Self::Pressure {
                triangles,
                pressure,
            } => pressure * follower::cone_volume(triangles, x, DVec3::ZERO),
            Self::Cable { path, tension } => tension * follower::path_length(path, x),
            Self::Chamber { .. } => self.chamber_energy(x),
        }
    }

    /// A chamber's liquid's energy (J) at the positions `x` (m); zero for other loads.
    fn chamber_energy(&self, x: &[DVec3]) -> f64 {
        match self {
            Self::Chamber {
                triangles,
                volume,
                bulk_modulus,
            } => chamber::energy(chamber::volume(triangles, x), (*volume, *bulk_modulus)),
            _ => 0.0,
        }
    }

    /// For a pressure on a closed surface or a chamber, the volume (m³) it encloses at the
    /// positions `x` (m): a cavity's volume, whose faces are oriented out of the body and so
    /// into the cavity. `None` for other loads; for an open surface the volume of the cone its
    /// triangles span from their centre.
    pub fn enclosed_volume(&self, x: &[DVec3]) -> Option<f64> {
        match self {
            Self::Pressure { triangles, .. } | Self::Chamber { triangles, .. } => {
                Some(chamber::volume(triangles, x))
            }
            _ => None,
        }
    }

    /// Adds to `rows[n]` a bound (N/m) on the row sum of the norms of the 3 x 3 blocks of the
    /// load's stiffness `−∂f/∂x` at node `n` at the positions `x` (m), for Gershgorin's bound on
    /// the highest frequency it adds: `2T/d` at each end of a cable segment of length `d` (its
    /// blocks `±T (I − d̂ d̂ᵀ)/d`), `|p| s/6` at each corner of a pressurized triangle of
    /// perimeter `s` (its blocks `(p/6) [x_c − x_b]ₓ`, `(p/6) [x_c − x_a]ₓ`, `(p/6) [x_b − x_a]ₓ`
    /// at corner `a`), and for a chamber that of its pressure and its liquid's rank-one term
    /// ([`chamber::add_stiffness_bounds`]); dead loads add nothing.
    pub(crate) fn add_stiffness_bounds(&self, x: &[DVec3], rows: &mut [f64]) {
        match self {
            Self::Pressure { triangles, .. } | Self::Chamber { triangles, .. } => {
                let pressure = self.pressure_at(x).unwrap_or(0.0);
                for &[a, b, c] in triangles {
                    let [xa, xb, xc] = [a, b, c].map(|n| x[n as usize]);
                    let perimeter = xa.distance(xb) + xb.distance(xc) + xc.distance(xa);
                    for n in [a, b, c] {
                        rows[n as usize] += pressure.abs() * perimeter / 6.0;
                    }
                }
                if let Self::Chamber {
                    volume,
                    bulk_modulus,
                    ..
                } = self
                {
                    chamber::add_stiffness_bounds(triangles, (*volume, *bulk_modulus), x, rows);
                }
            }
            Self::Cable { path, tension } => {
                for segment in path.windows(2) {
                    let length = x[segment[0] as usize].distance(x[segment[1] as usize]);
                    for &n in segment {
                        rows[n as usize] += 2.0 * tension / length;
                    }
                }
            }
            Self::Traction { .. } | Self::BodyForce { .. } => {}
        }
    }

    /// For a pressure on a closed, consistently oriented surface, the gradient `∂V/∂x` (m² per
    /// node) of the volume it encloses at the positions `x` (m): the force of a pressure of one
    /// pascal. `None` for other loads and open surfaces.
    pub(crate) fn cavity_volume_gradient(&self, x: &[DVec3]) -> Option<Vec<DVec3>> {
        let Self::Pressure { triangles, .. } = self else {
            return None;
        };
        follower::is_closed(triangles).then(|| chamber::volume_gradient(triangles, x))
    }

    /// For a chamber, its liquid's rank-one tangent `w g gᵀ` at the positions `x` (m): the
    /// gradient `g = ∇V` (m² per node) of its volume and `w = K/V*` (Pa/m³). `None` for other
    /// loads.
    pub(crate) fn chamber_term(&self, x: &[DVec3]) -> Option<(Vec<DVec3>, f64)> {
        match self {
            Self::Chamber {
                triangles,
                volume,
                bulk_modulus,
            } => Some((
                chamber::volume_gradient(triangles, x),
                bulk_modulus / volume,
            )),
            _ => None,
        }
    }

    /// The node pairs the load's tangent couples (`[a, b]`, `a > b`).
    pub(crate) fn coupled_pairs(&self) -> Vec<[u32; 2]> {
        let ordered = |a: u32, b: u32| if a > b { [a, b] } else { [b, a] };
        match self {
            Self::Pressure { triangles, .. } | Self::Chamber { triangles, .. } => triangles
                .iter()
                .flat_map(|&[a, b, c]| [ordered(a, b), ordered(b, c), ordered(c, a)])
                .collect(),
            Self::Cable { path, .. } => path.windows(2).map(|w| ordered(w[0], w[1])).collect(),
            Self::Traction { .. } | Self::BodyForce { .. } => Vec::new(),
        }
    }
}
