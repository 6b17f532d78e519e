//! The crate's typed errors: invalid data (meshes, materials, settings, time steps, states that
//! turned NaN) is reported with the element, node or parameter at fault, never as a panic. Asking
//! for a node or tetrahedron index that does not exist panics, as slice indexing does.

use std::fmt;
use thiserror::Error;

/// Where in a mesh file an import error was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileLocation {
    /// A line of a text file (1-based).
    Line(usize),
    /// A byte offset into the file (0-based), for binary data.
    Byte(usize),
    /// The file as a whole: the defect has no single place (no tetrahedra at all), or the
    /// parser that found it does not say where and no scan of the file could place it.
    Whole,
}

impl fmt::Display for FileLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Line(line) => write!(f, "line {line}"),
            Self::Byte(offset) => write!(f, "byte {offset}"),
            Self::Whole => write!(f, "file"),
        }
    }
}

/// What is wrong with a mesh file, see [`Error::MeshImport`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ImportErrorKind {
    /// The file ends before the data it announces.
    Truncated,
    /// A token is not what the format requires there (a number, a keyword, a section marker).
    Syntax,
    /// A count disagrees with the data or with another count.
    BadCount,
    /// Two nodes (or elements) carry the same identifier.
    DuplicateId,
    /// An element refers to a node that does not exist.
    IndexOutOfRange,
    /// A number is NaN or infinite, or becomes infinite once scaled.
    NonFinite,
    /// A coordinate is finite but lies beyond ±[`MAX_COORDINATE`](crate::limits::MAX_COORDINATE)
    /// m once scaled.
    CoordinateOutOfRange,
    /// An element type that cannot be used: quadratic tetrahedra, or volume elements other than
    /// tetrahedra (hexahedra, prisms, pyramids) mixed in.
    UnsupportedElement,
    /// A format version or variant this reader does not know (MSH 4.0, compressed data, ...).
    UnknownVersion,
    /// The file holds no tetrahedra.
    NoTetrahedra,
    /// A surface mesh that cannot be filled: empty, open or enclosing no volume.
    InvalidSurface,
    /// The file's extension names no format this crate reads.
    UnknownFormat,
    /// The file was read, but its tetrahedra do not make a valid mesh (a degenerate element).
    InvalidMesh,
}

/// Everything that can go wrong when building or stepping a soft body.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// The mesh has no nodes or no tetrahedra.
    #[error("the mesh is empty ({nodes} nodes, {tets} tetrahedra)")]
    EmptyMesh {
        /// Number of nodes given.
        nodes: usize,
        /// Number of tetrahedra given.
        tets: usize,
    },
    /// A node coordinate is NaN or infinite.
    #[error("node {node} has a non-finite coordinate {position:?}")]
    NonFiniteCoordinate {
        /// Index of the offending node.
        node: usize,
        /// Its coordinates (m).
        position: [f64; 3],
    },
    /// A node coordinate is finite but beyond ±[`MAX_COORDINATE`](crate::limits::MAX_COORDINATE)
    /// (m), where the products of coordinates the element computations form overflow.
    #[error(
        "node {node} at {position:?} m lies beyond ±{max:e} m, where the element computations overflow",
        max = crate::limits::MAX_COORDINATE
    )]
    CoordinateOutOfRange {
        /// Index of the offending node.
        node: usize,
        /// Its coordinates (m).
        position: [f64; 3],
    },
    /// A tetrahedron refers to a node that does not exist.
    #[error("tetrahedron {tet} refers to node {node}, but the mesh has {node_count} nodes")]
    NodeIndexOutOfRange {
        /// Index of the offending tetrahedron.
        tet: usize,
        /// The out-of-range node index.
        node: u32,
        /// Number of nodes in the mesh.
        node_count: usize,
    },
    /// A tetrahedron uses the same node twice.
    #[error("tetrahedron {tet} uses node {node} more than once")]
    RepeatedNode {
        /// Index of the offending tetrahedron.
        tet: usize,
        /// The repeated node.
        node: u32,
    },
    /// Two quadratic tetrahedra share an edge but put different mid-edge nodes on it.
    #[error(
        "tetrahedron {tet} puts node {node} at the middle of edge {corners:?}, where an earlier tetrahedron put node {other}"
    )]
    NonConformingEdge {
        /// Index of the offending element.
        tet: usize,
        /// The edge's corner nodes.
        corners: [u32; 2],
        /// The mid-edge node this element gives.
        node: u32,
        /// The mid-edge node an earlier element gave.
        other: u32,
    },
    /// A vertex of a mesh to embed lies outside the body's simulation mesh (farther than half a
    /// tetrahedron from its nearest simulation tetrahedron), so no element carries it.
    #[error(
        "vertex {vertex} of the embedded mesh, at {position:?}, lies outside the simulation mesh"
    )]
    OutsideSimulationMesh {
        /// Index of the offending vertex of the embedded mesh.
        vertex: usize,
        /// Its rest position (m).
        position: [f64; 3],
    },
    /// An option the body's other settings do not support.
    #[error("{option} is not supported here: {reason}")]
    UnsupportedOption {
        /// The option.
        option: &'static str,
        /// Why it does not apply.
        reason: &'static str,
    },
    /// A node belongs to no element (tetrahedron, or triangle of a 2D mesh): it would have no
    /// mass and no stiffness.
    #[error("node {node} belongs to no element")]
    UnreferencedNode {
        /// Index of the offending node.
        node: usize,
    },
    /// A triangle mesh has no nodes or no triangles.
    #[error("the triangle mesh is empty ({nodes} nodes, {triangles} triangles)")]
    EmptyTriangleMesh {
        /// Number of nodes given.
        nodes: usize,
        /// Number of triangles given.
        triangles: usize,
    },
    /// A triangle refers to a node that does not exist.
    #[error("triangle {triangle} refers to node {node}, but the mesh has {node_count} nodes")]
    TriangleNodeOutOfRange {
        /// Index of the offending triangle.
        triangle: usize,
        /// The out-of-range node index.
        node: u32,
        /// Number of nodes in the mesh.
        node_count: usize,
    },
    /// A triangle uses the same node twice.
    #[error("triangle {triangle} uses node {node} more than once")]
    TriangleRepeatedNode {
        /// Index of the offending triangle.
        triangle: usize,
        /// The repeated node.
        node: u32,
    },
    /// A triangle has (numerically) zero rest area: `|A| <= 1e-12 l²` with `l` its longest edge,
    /// or an area that is not a normal `f64`.
    #[error(
        "triangle {triangle} is degenerate: rest area {area:e} m^2 is zero at the mesh's scale"
    )]
    DegenerateTriangle {
        /// Index of the offending triangle.
        triangle: usize,
        /// Its signed rest area (m²).
        area: f64,
    },
    /// A triangle has negative rest area (its nodes are ordered clockwise).
    #[error(
        "triangle {triangle} is inverted: rest area {area:e} m^2 < 0 (order its nodes counterclockwise)"
    )]
    InvertedTriangle {
        /// Index of the offending triangle.
        triangle: usize,
        /// Its signed rest area (m²).
        area: f64,
    },
    /// A node's control area is not positive: circumcentric control volumes on a mesh whose
    /// obtuse triangles leave a node with a negative share of area (use median control volumes).
    #[error(
        "node {node} has a control area of {area:e} m^2: circumcentric control volumes need triangles that are not obtuse around it"
    )]
    NonPositiveControlArea {
        /// Index of the offending node.
        node: usize,
        /// Its control area (m²).
        area: f64,
    },
    /// A tetrahedron has (numerically) zero rest volume.
    #[error(
        "tetrahedron {tet} is degenerate: rest volume {volume:e} m^3 is zero at the mesh's scale"
    )]
    DegenerateTet {
        /// Index of the offending tetrahedron.
        tet: usize,
        /// Its signed rest volume (m^3).
        volume: f64,
    },
    /// A tetrahedron is too small for `f64`: the smallest volume it may have before counting as
    /// degenerate, `1e-12 l³` with `l` its longest edge, is not a normal number (`l` below about
    /// `3e-99` m), so its volume and everything computed from it would lose their precision.
    #[error(
        "tetrahedron {tet} is too small for f64: its longest edge is {longest_edge:e} m, and volumes at that scale are denormal numbers"
    )]
    TetTooSmall {
        /// Index of the offending tetrahedron.
        tet: usize,
        /// Its longest edge (m).
        longest_edge: f64,
    },
    /// A tetrahedron has negative rest volume (its nodes are ordered clockwise).
    /// [`TetMesh::new_reoriented`](crate::mesh::TetMesh::new_reoriented) fixes the ordering.
    #[error(
        "tetrahedron {tet} is inverted: rest volume {volume:e} m^3 < 0 (use TetMesh::new_reoriented to fix the node order)"
    )]
    InvertedTet {
        /// Index of the offending tetrahedron.
        tet: usize,
        /// Its signed rest volume (m^3).
        volume: f64,
    },
    /// A curved quadratic element folds: the Jacobian determinant of its rest map is not
    /// positive at a corner or a quadrature point (a mid-edge node too far off its edge for the
    /// element's size, or the corners ordered clockwise).
    #[error(
        "element {element} folds: its rest map's Jacobian determinant is {determinant:e} at a corner or quadrature point (a mid-edge node lies too far off its edge for the element's size)"
    )]
    FoldedElement {
        /// Index of the offending element.
        element: usize,
        /// A Jacobian determinant found not positive, or NaN (m³ per unit natural volume).
        determinant: f64,
    },
    /// A tetrahedron is too thin to simulate: its quality (smallest altitude over longest edge) is
    /// below the body's threshold.
    #[error(
        "tetrahedron {tet} is a sliver: quality {quality:.2e} is below the threshold {threshold:.2e}"
    )]
    SliverTet {
        /// Index of the offending tetrahedron.
        tet: usize,
        /// Its quality, smallest altitude over longest edge (dimensionless).
        quality: f64,
        /// The threshold it fell below.
        threshold: f64,
    },
    /// An element index given to a body (a region's material) does not exist.
    #[error("element {element} does not exist: the body has {element_count} elements")]
    ElementOutOfRange {
        /// The offending element index.
        element: usize,
        /// Number of elements in the body (tetrahedra, or quadratic elements).
        element_count: usize,
    },
    /// A region's material differs from its body's in more than Young's modulus and density.
    #[error(
        "a region's material must have its body's {what}: regions may change only Young's \
         modulus and density"
    )]
    RegionMaterialMismatch {
        /// What differs: the model or Poisson's ratio.
        what: &'static str,
    },
    /// A node index given to a body (pin, selection) does not exist.
    #[error("node {node} does not exist: the body has {node_count} nodes")]
    NodeOutOfRange {
        /// The offending node index.
        node: usize,
        /// Number of nodes in the body.
        node_count: usize,
    },
    /// A list of nodal values (positions, velocities) given to a body has the wrong length.
    #[error("{given} values were given for a body of {node_count} nodes")]
    WrongNodeCount {
        /// Number of values given.
        given: usize,
        /// Number of nodes in the body.
        node_count: usize,
    },
    /// A node velocity given to a body, or found on it before a step, is NaN or infinite.
    #[error("node {node} has a non-finite velocity {velocity:?} m/s")]
    NonFiniteVelocity {
        /// Index of the offending node.
        node: usize,
        /// Its velocity (m/s).
        velocity: [f64; 3],
    },
    /// A node speed given to a body, or found on it before a step, exceeds the speed of light
    /// ([`SPEED_OF_LIGHT`](crate::limits::SPEED_OF_LIGHT)): no state of the Newtonian mechanics
    /// the step integrates.
    #[error(
        "node {node} moves at {speed:e} m/s, faster than light ({c} m/s): beyond the Newtonian mechanics the step integrates",
        c = crate::limits::SPEED_OF_LIGHT
    )]
    SpeedOutOfRange {
        /// Index of the offending node.
        node: usize,
        /// Its speed (m/s).
        speed: f64,
    },
    /// A non-zero velocity was given to a pinned node, which the integrators hold at rest.
    #[error("node {node} is pinned: its velocity is held at zero, not {velocity:?} m/s")]
    PinnedNodeVelocity {
        /// Index of the pinned node.
        node: usize,
        /// The velocity given (m/s).
        velocity: [f64; 3],
    },
    /// A rigid body handle given to a soft body (attachment) is not in the rigid-body set.
    #[error("the rigid body is not in the rigid-body set")]
    UnknownRigidBody,
    /// A deformable body handle given to the coupling is not in the deformable-body set.
    #[error("the deformable body is not in the deformable-body set")]
    UnknownDeformableBody,
    /// A generator was asked for a shape it cannot mesh (zero cells, non-positive size).
    #[error("invalid mesh generator parameter `{parameter}` = {value}: {reason}")]
    InvalidGeneratorParameter {
        /// Name of the parameter.
        parameter: &'static str,
        /// The value given.
        value: f64,
        /// What it must satisfy.
        reason: &'static str,
    },
    /// The memory for a mesh cannot be had: the allocator refused it (a generator asked for
    /// more cells than the machine holds).
    #[error("cannot allocate {bytes} bytes for {what}")]
    AllocationFailed {
        /// What the memory was for.
        what: &'static str,
        /// The bytes asked for.
        bytes: u64,
    },
    /// A material or damping constant is outside its physical range.
    #[error("invalid material parameter `{parameter}` = {value}: {reason}")]
    InvalidMaterial {
        /// Name of the parameter.
        parameter: &'static str,
        /// The value given.
        value: f64,
        /// What it must satisfy.
        reason: &'static str,
    },
    /// A placement, velocity or load given to a body is NaN or infinite.
    #[error("`{parameter}` must be finite")]
    NonFiniteInput {
        /// Name of the input.
        parameter: &'static str,
    },
    /// A load cannot be applied as given (see [`crate::load::Load::check`]).
    #[error("{load}: {reason}")]
    InvalidLoad {
        /// The load's kind (`pressure`, `cable`, ...).
        load: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// A solver setting is outside its valid range.
    #[error("invalid setting `{parameter}` = {value}: {reason}")]
    InvalidSetting {
        /// Name of the setting.
        parameter: &'static str,
        /// The value given.
        value: f64,
        /// What it must satisfy.
        reason: &'static str,
    },
    /// The stability limit asks for more substeps than allowed: the material is too stiff, the
    /// damping too strong or an element too thin for explicit integration at this frame step.
    #[error(
        "a frame step of {frame_dt} s needs {needed} explicit substeps, more than the {max} allowed; use the implicit integrator or a coarser mesh"
    )]
    TooManySubsteps {
        /// The frame step (s).
        frame_dt: f64,
        /// Substeps the stability limit asks for.
        needed: f64,
        /// The configured maximum.
        max: u32,
    },
    /// A step flattened or inverted an element that was whole when it began (see
    /// [`integrate::COLLAPSE_RATIO`](crate::integrate::COLLAPSE_RATIO)): the load or impact is
    /// more than the material can hold at this mesh resolution. The step was refused.
    #[error(
        "the step crushed element {element} to a volume ratio J = {volume_ratio:.2e}; the step was refused and the previous state kept: the load or impact is more than the material can hold at this resolution (a stiffer material, a finer mesh or a slower impact)"
    )]
    ElementCrushed {
        /// The first element found crushed (a tetrahedron of a linear body, a quadratic element
        /// of a quadratic one, in the body's element order).
        element: usize,
        /// Its volume ratio `J` (dimensionless; negative when inverted): `V / V₀` for a linear
        /// tetrahedron, the smallest `det F` at the quadrature points of a quadratic element.
        volume_ratio: f64,
    },
    /// An implicit step's Newton solve did not meet its tolerance, even in the most substeps
    /// refinement allows. The step was refused.
    #[error(
        "the implicit step's Newton solve stopped at a relative residual of {residual:.2e}, short of its tolerance, even in {substeps} substeps per frame; the step was refused and the previous state kept"
    )]
    NewtonDidNotConverge {
        /// The relative residual where it stopped (dimensionless).
        residual: f64,
        /// Substeps per frame of the last attempt.
        substeps: u32,
    },
    /// A surface point ended an implicit step past the middle of the collider it touches (too
    /// fast for the contact to hold), even in the most substeps refinement allows. The step was
    /// refused.
    #[error(
        "a surface point ended the step past the middle of the collider it touches even in {substeps} substeps per frame; the step was refused and the previous state kept"
    )]
    ContactNotResolved {
        /// Substeps per frame of the last attempt.
        substeps: u32,
    },
    /// Every node is pinned: there is nothing to solve for.
    #[error("every node is pinned")]
    NoFreeNode,
    /// A time step is not usable.
    #[error("invalid time step {dt} s: {reason}")]
    InvalidTimeStep {
        /// The step given (s).
        dt: f64,
        /// What it must satisfy.
        reason: &'static str,
    },
    /// Stepping produced a NaN or infinite state; the step was rejected and the state before it kept.
    #[error(
        "stepping produced a non-finite state at node {node}; the step was rejected and the previous state kept"
    )]
    NonFiniteState {
        /// First node found with a non-finite position or velocity.
        node: usize,
    },
    /// A Newton solver (static equilibrium, implicit step) or the modal analysis met a matrix it
    /// cannot factor (not positive definite), e.g. the stiffness of a body with no pinned node.
    #[error("the tangent stiffness is not positive definite at Newton iteration {iteration}")]
    IndefiniteStiffness {
        /// Newton iteration (0-based) at which factorization failed.
        iteration: usize,
    },
    /// A mesh file is malformed or holds what this crate cannot use.
    #[error("{path}: {location}: {message}")]
    MeshImport {
        /// The file, as given.
        path: String,
        /// Where in the file.
        location: FileLocation,
        /// What kind of defect.
        kind: ImportErrorKind,
        /// What is wrong, in words.
        message: String,
    },
    /// A mesh file's region (Gmsh physical group) asked for by name or tag is not there, is
    /// ambiguous, or is not of the kind asked (a body's mesh needs a volume).
    #[error("{path}: {region}: {reason}")]
    MeshRegion {
        /// The file, as given.
        path: String,
        /// The region asked for (`region "clamp"`, `region tag 2`).
        region: String,
        /// Why it cannot be used, with the file's regions where that helps.
        reason: String,
    },
    /// A file could not be read (missing, unreadable).
    #[error("{path}: {message}")]
    Io {
        /// The file, as given.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// The static solver did not reach its tolerance.
    #[error(
        "static solve did not converge in {iterations} Newton iterations (relative residual {residual:e})"
    )]
    StaticSolveDidNotConverge {
        /// Iterations performed.
        iterations: usize,
        /// Final residual norm over the load norm.
        residual: f64,
    },
}

impl Error {
    /// The checks every step makes before it starts: a positive, finite frame step `frame_dt`
    /// (s) and a finite `gravity` (m/s²).
    pub(crate) fn check_step(frame_dt: f64, gravity: rapier3d::glamx::DVec3) -> Result<(), Self> {
        if !(frame_dt.is_finite() && frame_dt > 0.0) {
            return Err(Self::InvalidTimeStep {
                dt: frame_dt,
                reason: "must be positive and finite",
            });
        }
        if !gravity.is_finite() {
            return Err(Self::NonFiniteInput {
                parameter: "gravity",
            });
        }
        Ok(())
    }
}
