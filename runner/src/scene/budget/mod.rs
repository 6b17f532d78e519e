//! The memory a scene's soft bodies need, estimated from the sizes of their meshes before any is
//! built, against the memory the machine has: a scene of `cells = [1500, 1500, 1500]` is refused
//! with its estimate instead of aborting on an allocation of tens of gigabytes.
//!
//! Contract: the checker counts the nodes and tetrahedra of every generated mesh from its cell
//! counts (the generators' own formulas, upper bounds for cylinders and spheres), and of every
//! surface file from its fill lattice (`cells_across`), in `f64` so that no count overflows;
//! [`Simulation::build`](crate::sim::Simulation::build) counts the meshes read from volume files
//! once read, before a body is built of them. The count is priced at bytes measured on real runs
//! ([`BYTES_PER_TET`], [`BYTES_PER_NODE`], [`BYTES_PER_HEXAHEDRON`], [`BASE_BYTES`]) and refused
//! when it exceeds the [`MemoryBudget`].

mod count;

pub use count::{estimate_embedded, estimate_mesh};

use super::check::Checker;
use super::error::{SceneError, SceneSource};
use super::soft_body::SoftBodySpec;
use rapier_fvm::mesh::TetMesh;

/// Bytes of a run that do not grow with its meshes (binary, rapier, picture buffers): the peak
/// resident size of `rapier-fvm run` on a scene of one cube of 5 tetrahedra, 19.3 MB, rounded up.
pub const BASE_BYTES: f64 = 20e6;

/// Bytes per tetrahedron of a body's mesh (the elements, or the subdivision of quadratic ones).
///
/// Measured with `/usr/bin/time -v rapier-fvm run` (peak resident size) over two frames on
/// cuboids of linear tetrahedra, 10³ to 70³ cells (5 000 to 1.7 million tetrahedra) and bars of
/// 20 000 and 60 000 x 1 x 1 cells, explicit and implicit: with [`BYTES_PER_NODE`], the upper
/// envelope of the peaks minus [`BASE_BYTES`]. It over-estimates the implicit runs by 1 to 37 %
/// (cube 70³: 2.23 GB measured, 3.04 GB estimated), the explicit ones by up to 70 %; it covers
/// quadratic tetrahedra (20³ cells: 502 MB measured, 552 MB estimated).
pub const BYTES_PER_TET: f64 = 1250.0;

/// Bytes per node of a body's mesh; measured with [`BYTES_PER_TET`].
pub const BYTES_PER_NODE: f64 = 2500.0;

/// Bytes per quadratic hexahedron of a cage, beyond its subdivision's tetrahedra and nodes:
/// measured on a cage of 20³ cells (8 000 hexahedra, 68 921 nodes) stepped implicitly, 823 MB
/// (explicitly 486 MB), which this prices at 828 MB.
pub const BYTES_PER_HEXAHEDRON: f64 = 32_000.0;

/// The budget where the memory available cannot be read (no `/proc/meminfo`): 8 GB.
pub const FALLBACK_BYTES: f64 = 8e9;

/// What a scene's soft bodies hold, counted in `f64`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MeshCount {
    /// Nodes.
    pub nodes: f64,
    /// Tetrahedra (of the subdivision, for quadratic elements).
    pub tets: f64,
    /// Quadratic hexahedra of cages.
    pub hexahedra: f64,
}

impl MeshCount {
    /// The count of a built mesh (rest positions in m) with `hexahedra` cage elements on it.
    pub fn of(mesh: &TetMesh, hexahedra: usize) -> Self {
        Self {
            nodes: mesh.node_count() as f64,
            tets: mesh.tet_count() as f64,
            hexahedra: hexahedra as f64,
        }
    }

    /// The estimated memory (bytes) of bodies of this count, [`BASE_BYTES`] included.
    pub fn bytes(&self) -> f64 {
        BASE_BYTES
            + BYTES_PER_TET * self.tets
            + BYTES_PER_NODE * self.nodes
            + BYTES_PER_HEXAHEDRON * self.hexahedra
    }

    /// The sum of two counts.
    pub fn plus(self, other: Self) -> Self {
        Self {
            nodes: self.nodes + other.nodes,
            tets: self.tets + other.tets,
            hexahedra: self.hexahedra + other.hexahedra,
        }
    }
}

/// Where a [`MemoryBudget`] comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BudgetOrigin {
    /// `MemAvailable` in `/proc/meminfo` (Linux).
    Available,
    /// [`FALLBACK_BYTES`], the memory available being unknown.
    Fallback,
    /// Given by the user (`run --memory-limit`).
    Given,
}

/// The most memory a scene may need (bytes), and where that figure comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MemoryBudget {
    /// Bytes.
    pub bytes: f64,
    /// Where the figure comes from.
    pub origin: BudgetOrigin,
}

impl Default for MemoryBudget {
    /// [`MemoryBudget::available`].
    fn default() -> Self {
        Self::available()
    }
}

impl MemoryBudget {
    /// The memory available now: `MemAvailable` of `/proc/meminfo`, else [`FALLBACK_BYTES`].
    pub fn available() -> Self {
        std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|text| mem_available(&text))
            .map_or(
                Self {
                    bytes: FALLBACK_BYTES,
                    origin: BudgetOrigin::Fallback,
                },
                |bytes| Self {
                    bytes,
                    origin: BudgetOrigin::Available,
                },
            )
    }

    /// A budget of `bytes` given by the user.
    pub fn given(bytes: f64) -> Self {
        Self {
            bytes,
            origin: BudgetOrigin::Given,
        }
    }

    /// Why bodies of `count` do not fit, if they do not: the estimate against the budget.
    pub fn refusal(&self, count: MeshCount) -> Option<String> {
        let needed = count.bytes();
        (needed > self.bytes).then(|| {
            let origin = match self.origin {
                BudgetOrigin::Available => "available (MemAvailable in /proc/meminfo)",
                BudgetOrigin::Fallback => "allowed where the memory available is unknown",
                BudgetOrigin::Given => "allowed by --memory-limit",
            };
            format!(
                "the soft bodies would need about {} ({:.0} nodes, {:.0} tetrahedra{}), more than \
                 the {} {origin}; use fewer cells, or raise the limit with run --memory-limit (GB)",
                gigabytes(needed),
                count.nodes,
                count.tets,
                if count.hexahedra > 0.0 {
                    format!(", {:.0} hexahedra", count.hexahedra)
                } else {
                    String::new()
                },
                gigabytes(self.bytes),
            )
        })
    }
}

/// `MemAvailable` (bytes) from the text of `/proc/meminfo`.
fn mem_available(meminfo: &str) -> Option<f64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let mut words = line.split_whitespace().skip(1);
    let value: f64 = words.next()?.parse().ok()?;
    (words.next() == Some("kB")).then_some(value * 1024.0)
}

/// `bytes` in GB (10⁹ bytes), three significant figures at least.
fn gigabytes(bytes: f64) -> String {
    format!("{:.3} GB", bytes / 1e9)
}

/// Fails at the first key of `bodies` (a mesh, an embedded mesh) that takes their count, summed
/// in order, over `budget`.
pub(crate) fn check(bodies: &[SoftBodySpec], budget: &MemoryBudget, c: &mut Checker<'_>) {
    let mut total = MeshCount::default();
    for (i, body) in bodies.iter().enumerate() {
        let mut parts = vec![(
            format!("soft_body[{i}].mesh"),
            estimate_mesh(&body.mesh, body.elements),
        )];
        if let Some(embedded) = &body.embedded {
            parts.push((
                format!("soft_body[{i}].embedded"),
                estimate_embedded(embedded),
            ));
        }
        for (key, count) in parts {
            total = total.plus(count);
            if let Some(message) = budget.refusal(total) {
                c.fail(&key, message);
                return;
            }
        }
    }
}

/// The count of the meshes built so far, against the budget: what
/// [`Simulation::build`](crate::sim::Simulation::build) checks as it reads mesh files.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MemoryUse {
    budget: MemoryBudget,
    total: MeshCount,
}

impl MemoryUse {
    /// Nothing built yet, against `budget`.
    pub(crate) fn new(budget: MemoryBudget) -> Self {
        Self {
            budget,
            total: MeshCount::default(),
        }
    }

    /// Adds a built mesh's `count`, or refuses it at `key` if the total would exceed the budget.
    pub(crate) fn add(
        &mut self,
        count: MeshCount,
        key: &str,
        source: &SceneSource,
    ) -> Result<(), SceneError> {
        let total = self.total.plus(count);
        match self.budget.refusal(total) {
            Some(message) => Err(source.error(key, message)),
            None => {
                self.total = total;
                Ok(())
            }
        }
    }
}
