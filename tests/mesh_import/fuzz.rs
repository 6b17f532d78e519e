//! Fuzzing of every reader: arbitrary bytes, mutations of the valid files and every truncation
//! of their headers must give a mesh or a typed error, never a panic.

use super::bytes;
use super::file_numbers::assert_mesh_is_the_files;
use proptest::prelude::*;
use rapier_fvm::mesh::import::{
    Hexahedra, RawMesh, RegionId, SurfaceOptions, gmsh, surface, tetgen, vtk,
};
use rapier_fvm::prelude::*;
use rapier_fvm::{FileLocation, ImportErrorKind};

// Fuzzing: arbitrary bytes and mutations of the valid files, for every reader. Each must
// return Ok or a typed error, never panic (a panic fails the test); a mesh must be the file's
// (its tetrahedra, nodes and volume, see `file_numbers`). The number of executions
// is `cases` of each property below; the total is printed by `fuzz_execution_count`. A long run
// of one format: `FUZZ_READER=3 PROPTEST_CASES=500000 cargo test --release --test mesh_import
// fuzz_mutated` (two properties of 500 000 mutated VTU files each).

/// Cases per fuzz property: 10 000, or `PROPTEST_CASES` (for longer runs).
fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(10_000)
}

fn run_reader(reader: usize, data: &[u8]) {
    let result = match reader {
        // As `load` reads a `.msh` file: a surface-only one is filled.
        0 => gmsh::parse(data, "fuzz.msh", 1.0).or_else(|e| match e {
            Error::MeshImport {
                kind: ImportErrorKind::NoTetrahedra,
                ..
            } => gmsh::parse_surface(data, "fuzz.msh", 1.0)
                .and_then(|s| surface::fill(&s, &SurfaceOptions { cells_across: 4 })),
            other => Err(other),
        }),
        1 => tetgen::parse(data, "fuzz.node", &bytes_cached_ele(), "cube.ele", 1.0),
        2 => tetgen::parse(&bytes_cached_node(), "cube.node", data, "fuzz.ele", 1.0),
        3 => vtk::parse_vtu(data, "fuzz.vtu", 1.0),
        4 => vtk::parse_legacy(data, "fuzz.vtk", 1.0),
        5 => located(surface::parse_obj(data, "fuzz.obj", 1.0))
            .and_then(|s| surface::fill(&s, &SurfaceOptions { cells_across: 4 })),
        _ => located(surface::parse_stl(data, "fuzz.stl", 1.0))
            .and_then(|s| surface::fill(&s, &SurfaceOptions { cells_across: 4 })),
    };
    let outcome = result.and_then(|raw| Ok((raw.clone(), raw.into_mesh()?)));
    match outcome {
        Ok((raw, mesh)) => {
            assert_mesh_is_the_files(&raw, &mesh);
            assert_regions_fit(&raw, mesh.node_count());
            assert_cage_builds(&raw);
        }
        Err(e @ Error::MeshImport { .. }) => {
            // One line of printable text, whatever bytes the file held.
            let shown = e.to_string();
            assert!(!shown.chars().any(char::is_control), "{shown:?}");
        }
        Err(Error::InvalidSetting { .. }) => {}
        Err(other) => panic!("untyped import error {other:?}"),
    }
}

/// Every region's nodes, renumbered, are nodes of the mesh of `node_count` nodes and its
/// tetrahedra the file's; every volume region keeps alone into a mesh or a typed error.
fn assert_regions_fit(raw: &RawMesh, node_count: usize) {
    for region in raw.regions_in_mesh() {
        assert!(region.nodes.iter().all(|&n| (n as usize) < node_count));
        assert!(region.tets.iter().all(|&t| (t as usize) < raw.tets.len()));
        if region.dimension == 3 {
            let kept = raw.clone().keep_volume(&RegionId::Tag(region.tag));
            match kept.and_then(RawMesh::into_mesh) {
                Ok(_) | Err(Error::MeshRegion { .. } | Error::MeshImport { .. }) => {}
                Err(other) => panic!("untyped region error {other:?}"),
            }
        }
    }
}

/// A file of hexahedra makes a cage (its regions widened onto it) or a typed error.
fn assert_cage_builds(raw: &RawMesh) {
    if raw.hexahedra == Hexahedra::None {
        return;
    }
    let regions = raw.regions_in_mesh();
    match raw.clone().into_cage() {
        Ok(cage) => {
            for region in regions {
                let widened = region.with_cage_nodes(&cage);
                assert!(
                    widened
                        .nodes
                        .iter()
                        .all(|&n| (n as usize) < cage.node_count())
                );
            }
        }
        Err(Error::MeshImport { .. }) => {}
        Err(other) => panic!("untyped cage error {other:?}"),
    }
}

/// `result`, after checking that an error of the OBJ or STL reader says where: their
/// locators must find every statement `tobj` or `stl_io` rejects.
fn located(result: Result<surface::Surface, Error>) -> Result<surface::Surface, Error> {
    if let Err(e @ Error::MeshImport { location, .. }) = &result {
        assert_ne!(*location, FileLocation::Whole, "unplaced error: {e}");
    }
    result
}

fn bytes_cached_node() -> Vec<u8> {
    static NODE: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    NODE.get_or_init(|| bytes("cube.node")).clone()
}

fn bytes_cached_ele() -> Vec<u8> {
    static ELE: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    ELE.get_or_init(|| bytes("cube.ele")).clone()
}

/// (reader, valid file) pairs mutated by the fuzz properties.
const SEEDS: [(usize, &str); 37] = [
    (0, "cube_v22_ascii.msh"),
    (0, "cube_v22_binary.msh"),
    (0, "cube_v41_ascii.msh"),
    (0, "cube_v41_binary.msh"),
    (0, "cube_v40_ascii.msh"),
    (0, "cube_v22_parametric.msh"),
    (0, "sphere_surface.msh"),
    (0, "cube_regions_v22.msh"),
    (0, "cube_regions_v41_binary.msh"),
    (0, "two_volumes_v41.msh"),
    (0, "box_hex8_v41.msh"),
    (0, "box_hex8_v22_binary.msh"),
    (0, "box_hex27_v41.msh"),
    (1, "cube.node"),
    (1, "two_volumes_meshio.node"),
    (2, "cube.ele"),
    (3, "cube_ascii.vtu"),
    (3, "cube_binary.vtu"),
    (3, "cube_zlib.vtu"),
    (3, "cube_vtk_appended_base64.vtu"),
    (3, "cube_vtk_appended_raw_zlib.vtu"),
    (3, "cube_vtk_zlib_small_blocks.vtu"),
    (3, "cube_vtk_binary_uint32.vtu"),
    (3, "two_volumes_meshio.vtu"),
    (3, "box_hex27_meshio.vtu"),
    (3, "cube_tet10_ascii.vtu"),
    (3, "cube_vtk_appended_raw.vtu"),
    (4, "cube_ascii.vtk"),
    (4, "cube_binary.vtk"),
    (4, "cube_vtk9_legacy.vtk"),
    (4, "two_volumes_meshio.vtk"),
    (4, "box_hex27_vtk9.vtk"),
    (4, "cube_vtk9_legacy_binary.vtk"),
    (5, "sphere.obj"),
    (6, "cube.stl"),
    (6, "sphere_ascii.stl"),
    (6, "cube_multi_solid.stl"),
];

/// The seeds the mutation properties draw from: all, or those of the reader numbered
/// `FUZZ_READER` (0 Gmsh, 1 and 2 `TetGen` `.node` and `.ele`, 3 VTU, 4 legacy VTK, 5 OBJ,
/// 6 STL), to fuzz one format at length (with `PROPTEST_CASES`).
fn seed_files() -> impl Strategy<Value = usize> {
    let reader: Option<usize> = std::env::var("FUZZ_READER")
        .ok()
        .and_then(|r| r.parse().ok());
    let files: Vec<usize> = (0..SEEDS.len())
        .filter(|&i| reader.is_none_or(|r| SEEDS[i].0 == r))
        .collect();
    assert!(!files.is_empty(), "FUZZ_READER names no reader with seeds");
    prop::sample::select(files)
}

fn seed(index: usize) -> (usize, Vec<u8>) {
    static FILES: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    let files = FILES.get_or_init(|| SEEDS.iter().map(|(_, name)| bytes(name)).collect());
    (SEEDS[index].0, files[index].clone())
}

/// A mutation of a valid file: truncation, byte overwrites, or a number replaced by an extreme
/// one.
#[derive(Debug, Clone)]
enum Mutation {
    Truncate(prop::sample::Index),
    Bytes(Vec<(prop::sample::Index, u8)>),
    Number(prop::sample::Index, &'static str),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<prop::sample::Index>().prop_map(Mutation::Truncate),
        prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..4)
            .prop_map(Mutation::Bytes),
        (
            any::<prop::sample::Index>(),
            prop::sample::select(vec![
                "0",
                "-1",
                "1",
                "2",
                "4000000000",
                "18446744073709551615",
                "99999999999999999999",
                "nan",
                "inf",
                "-1e308",
                "1e308",
                "11",
                "5",
                "10",
                "24",
                "3",
            ])
        )
            .prop_map(|(i, n)| Mutation::Number(i, n)),
    ]
}

fn mutate(data: &[u8], mutation: &Mutation) -> Vec<u8> {
    match mutation {
        Mutation::Truncate(at) => data[..at.index(data.len() + 1)].to_vec(),
        Mutation::Bytes(changes) => {
            let mut data = data.to_vec();
            for (at, byte) in changes {
                let i = at.index(data.len());
                data[i] = *byte;
            }
            data
        }
        Mutation::Number(at, number) => {
            // Replace the run of digits at or after a position by `number`.
            let start = at.index(data.len());
            let Some(first) = data[start..].iter().position(u8::is_ascii_digit) else {
                return data.to_vec();
            };
            let first = start + first;
            let end = first
                + data[first..]
                    .iter()
                    .position(|b| !b.is_ascii_digit())
                    .unwrap_or(data.len() - first);
            [&data[..first], number.as_bytes(), &data[end..]].concat()
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn fuzz_arbitrary_bytes(reader in 0usize..7, data in prop::collection::vec(any::<u8>(), 0..512)) {
        run_reader(reader, &data);
    }

    #[test]
    fn fuzz_arbitrary_text(reader in 0usize..7, data in "[ -~\n]{0,300}") {
        run_reader(reader, data.as_bytes());
    }

    #[test]
    fn fuzz_mutated_files(file in seed_files(), mutation in mutation()) {
        let (reader, data) = seed(file);
        run_reader(reader, &mutate(&data, &mutation));
    }

    #[test]
    fn fuzz_mutated_headers(file in seed_files(), mutation in mutation()) {
        // The same mutations within the first 400 bytes, where the counts and versions are.
        let (reader, data) = seed(file);
        let head = data.len().min(400);
        let mut mutated = mutate(&data[..head], &mutation);
        mutated.extend_from_slice(&data[head..]);
        run_reader(reader, &mutated);
    }
}

/// Truncation at every length of the Gmsh and VTK cube files' first 4 kB and of the `TetGen`
/// files: every prefix must give a typed error (or, for a prefix that is a whole file, a mesh).
#[test]
fn fuzz_every_truncation_of_the_headers() {
    let mut executions = 0;
    for index in 0..SEEDS.len() {
        let (reader, data) = seed(index);
        for len in 0..data.len().min(4096) {
            run_reader(reader, &data[..len]);
            executions += 1;
        }
    }
    println!("truncations executed: {executions}");
}

#[test]
fn fuzz_execution_count() {
    // 4 properties of `cases()` cases each, plus the truncations (printed by their test).
    println!("proptest fuzz executions: {}", 4 * cases());
}
