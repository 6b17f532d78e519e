//! The 2D scene reader fuzzed from the shipped 2D scenes as seeds: a number replaced by an
//! adversarial value (zero, negative, NaN, infinities, huge, tiny, large counts) or a line
//! dropped or repeated. Reading and building never panic: each mutant is read and built, or
//! refused with an error naming the file, and a line when it has one.

use rapier_fvm_runner::planar::{PlanarScene, PlanarSimulation};
use std::path::Path;

/// The shipped 2D scenes the mutants start from.
const SEEDS: [&str; 2] = ["planar_drop.toml", "planar_rolling_disk.toml"];

/// Values a number is replaced by.
const VALUES: [&str; 12] = [
    "0", "-1", "nan", "inf", "-inf", "1e300", "1e-300", "0.5", "3", "16384", "1e7", "-0.0",
];

/// The byte ranges of the numbers in `text` (outside comments).
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let mut found = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let code = line.split('#').next().unwrap_or("");
        let bytes = code.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            let starts = bytes[i].is_ascii_digit()
                || (bytes[i] == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
            let after_word =
                i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
            if starts && !after_word {
                let mut j = i + 1;
                while j < bytes.len() && (bytes[j].is_ascii_digit() || b".eE+-".contains(&bytes[j]))
                {
                    j += 1;
                }
                found.push((offset + i, offset + j));
                i = j;
            } else {
                i += 1;
            }
        }
        offset += line.len();
    }
    found
}

/// `text` mutated by `operation` at position `at` with value `value`.
fn mutate(text: &str, (operation, at, value): (u8, usize, usize)) -> String {
    match operation {
        0 | 1 => {
            let spans = numbers(text);
            let (start, end) = spans[at % spans.len()];
            format!(
                "{}{}{}",
                &text[..start],
                VALUES[value % VALUES.len()],
                &text[end..]
            )
        }
        _ => {
            let lines: Vec<&str> = text.lines().collect();
            let k = at % lines.len();
            let mut out: Vec<&str> = lines.clone();
            if operation == 2 {
                out.remove(k);
            } else {
                out.insert(k, lines[k]);
            }
            out.join("\n")
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

    /// A mutant of a shipped 2D scene is read and built, or refused with an error that names
    /// the file (and never a panic).
    #[test]
    fn mutated_2d_scenes_are_built_or_refused(
        seed in 0usize..SEEDS.len(),
        operation in 0u8..4,
        at in 0usize..10_000,
        value in 0usize..VALUES.len(),
    ) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes").join(SEEDS[seed]);
        let text = std::fs::read_to_string(&path).unwrap();
        let mutant = mutate(&text, (operation, at, value));
        let refused = match PlanarScene::parse("scenes/mutant.toml", mutant) {
            Ok(scene) => PlanarSimulation::build(&scene).err(),
            Err(error) => Some(error),
        };
        if let Some(error) = refused {
            proptest::prop_assert!(error.to_string().starts_with("scenes/mutant.toml"), "{error}");
        }
    }
}

/// The scanner finds the numbers of a line and skips names and comments.
#[test]
fn the_scanner_finds_numbers_not_names() {
    let text = "a1 = [0.5, -2e3] # 7\nb = 4\n";
    let spans: Vec<&str> = numbers(text).iter().map(|&(s, e)| &text[s..e]).collect();
    assert_eq!(spans, ["0.5", "-2e3", "4"]);
}
