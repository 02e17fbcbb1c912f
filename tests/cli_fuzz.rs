//! Fuzzing the command line's numbers (issue 16): every numeric option of `render`, `bench flight`, `bench kernel`
//! and `export` given arbitrary text, special values (empty, signs, zero, NaN, infinities, overflowing and tiny
//! numbers, words) or arbitrary numbers, one at a time. The run never panics, dies of a signal or hangs; it either
//! works or exits 2 with a message that names the option (or the output path, when the output goes to a folder
//! that does not exist, which is refused before any work). Two properties: many fast runs into a missing folder
//! (what the parsers refuse), and a few real runs of values near the valid ranges on a small planet (what they
//! accept must work).

use std::process::{Command, Output};

use proptest::prelude::*;

/// (command, option, what kind of value it takes).
const OPTIONS: [(&str, &str, Kind); 19] = [
    ("render", "--seed", Kind::Number),
    ("render", "--eye", Kind::Vector),
    ("render", "--look-at", Kind::Vector),
    ("render", "--up", Kind::Vector),
    ("render", "--fov", Kind::Number),
    ("render", "--size", Kind::Size),
    ("render", "--sun-elevation", Kind::Number),
    ("render", "--time", Kind::Number),
    ("render", "--clear-color", Kind::Vector),
    ("render", "--max-frames", Kind::Number),
    ("bench flight", "--frames", Kind::Number),
    ("bench flight", "--speed", Kind::Number),
    ("bench flight", "--size", Kind::Size),
    ("bench flight", "--frames-in-flight", Kind::Number),
    ("bench kernel", "--frames", Kind::Number),
    ("export faces", "--level", Kind::Number),
    ("export equirect", "--size", Kind::Size),
    ("export region", "--bounds", Kind::Bounds),
    ("export region", "--level", Kind::Number),
];

#[derive(Clone, Copy, Debug)]
enum Kind {
    Number,
    Vector,
    Size,
    Bounds,
}

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        Just(String::new()),
        Just("-".to_string()),
        Just("0".to_string()),
        Just("-0".to_string()),
        Just("-1".to_string()),
        Just("NaN".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("1e39".to_string()),
        Just("1e-50".to_string()),
        Just("4294967296".to_string()),
        Just("ten".to_string()),
        (-1000i64..1000).prop_map(|n| n.to_string()),
        any::<i64>().prop_map(|n| n.to_string()),
        any::<f64>().prop_map(|x| x.to_string()),
        (-5.0f64..5.0).prop_map(|x| format!("{x:.3}")),
    ]
}

fn value(kind: Kind) -> BoxedStrategy<String> {
    match kind {
        Kind::Number => number().boxed(),
        Kind::Vector => prop_oneof![
            prop::collection::vec(number(), 3).prop_map(|v| v.join(",")),
            prop::collection::vec(number(), 0..5).prop_map(|v| v.join(",")),
        ]
        .boxed(),
        Kind::Size => prop_oneof![
            (number(), number()).prop_map(|(w, h)| format!("{w}x{h}")),
            (1u32..40, 1u32..40).prop_map(|(w, h)| format!("{w}x{h}")),
            number(),
        ]
        .boxed(),
        Kind::Bounds => prop_oneof![
            prop::collection::vec(number(), 4).prop_map(|v| v.join(",")),
            prop::collection::vec(-200.0f64..200.0, 4).prop_map(|v| v
                .iter()
                .map(|x| format!("{x:.2}"))
                .collect::<Vec<_>>()
                .join(",")),
        ]
        .boxed(),
    }
}

fn case() -> impl Strategy<Value = (usize, String)> {
    (0..OPTIONS.len()).prop_flat_map(|k| (Just(k), value(OPTIONS[k].2)))
}

/// Values near the valid ranges, so that most are accepted and run.
fn plausible(kind: Kind) -> BoxedStrategy<String> {
    let small = prop_oneof![
        (0u32..12).prop_map(|n| n.to_string()),
        (-100.0f64..100.0).prop_map(|x| format!("{x:.2}")),
    ];
    match kind {
        Kind::Number => small.boxed(),
        Kind::Vector => prop::collection::vec(-3000.0f64..3000.0, 3)
            .prop_map(|v| format!("{:.1},{:.1},{:.1}", v[0], v[1], v[2]))
            .boxed(),
        Kind::Size => (1u32..24, 1u32..24)
            .prop_map(|(w, h)| format!("{w}x{h}"))
            .boxed(),
        Kind::Bounds => prop::collection::vec(-30.0f64..30.0, 4)
            .prop_map(|v| format!("{:.1},{:.1},{:.1},{:.1}", v[0], v[1], v[2], v[3]))
            .boxed(),
    }
}

fn plausible_case() -> impl Strategy<Value = (usize, String)> {
    (0..OPTIONS.len()).prop_flat_map(|k| (Just(k), plausible(OPTIONS[k].2)))
}

/// The output option of a command and the arguments that keep a real run small.
fn output_and_limits(command: &str) -> (&'static str, &'static str, Vec<&'static str>) {
    match command {
        "render" => ("--out", "x.png", vec!["--size", "8x8", "--max-frames", "1"]),
        "bench flight" => (
            "--json",
            "x.json",
            vec![
                "--frames",
                "2",
                "--size",
                "8x8",
                "--no-kernel-comparison",
                "--no-water-comparison",
                "--summary-only",
            ],
        ),
        "bench kernel" => ("--json", "x.json", vec!["--frames", "1"]),
        "export faces" => ("--out", "faces", vec!["--level", "0"]),
        "export equirect" => ("--out", "x.tiff", vec!["--size", "8x4", "--level", "0"]),
        _ => (
            "--out",
            "x.tiff",
            vec!["--bounds", "0,0,1,1", "--level", "2"],
        ),
    }
}

/// A small planet (base lattice 33, four levels, the thesis's rivers): a real run takes about a second.
fn small_planet(dir: &std::path::Path) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let config = dir.join("small.xml");
    std::fs::write(
        &config,
        "<planet><planet-attributes><base-resolution>33</base-resolution></planet-attributes>\
         <rendering-attributes><max-level-of-detail>4</max-level-of-detail></rendering-attributes>\
         <river-attributes><river-model>thesis</river-model></river-attributes></planet>",
    )
    .unwrap();
    config
}

/// Runs `riverplanet COMMAND --config CONFIG LIMITS OPTION=VALUE OUTPUT` (a limit on the fuzzed option itself left
/// out) writing into `out_dir`, under a time limit.
fn run(k: usize, value: &str, config: &std::path::Path, out_dir: &std::path::Path) -> Output {
    let (command, option, _) = OPTIONS[k];
    let (output, file, mut limits) = output_and_limits(command);
    if let Some(at) = limits.iter().position(|a| *a == option) {
        limits.drain(at..at + 2);
    }
    Command::new("timeout")
        .arg("120")
        .arg(env!("CARGO_BIN_EXE_riverplanet"))
        .args(command.split(' '))
        .arg("--config")
        .arg(config)
        .args(limits)
        .arg(format!("{option}={value}"))
        .arg(output)
        .arg(out_dir.join(file))
        .output()
        .unwrap()
}

/// No panic, no signal, no hang (`timeout` exits 124); success, or exit 2 naming the option or the output.
fn check(k: usize, value: &str, run: &Output) -> Result<(), TestCaseError> {
    let (command, option, _) = OPTIONS[k];
    let (output, _, _) = output_and_limits(command);
    let stderr = String::from_utf8_lossy(&run.stderr);
    let what = format!("{command} {option}={value}: {:?} {stderr}", run.status);
    prop_assert!(!stderr.contains("panicked"), "{}", what);
    match run.status.code() {
        Some(0) => {}
        Some(2) => prop_assert!(
            stderr.contains(option) || stderr.contains(output),
            "{}",
            what
        ),
        _ => prop_assert!(false, "{}", what),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, failure_persistence: None, ..ProptestConfig::default() })]

    /// Into a folder that does not exist: what the parsers refuse is named; the rest stops at the output path.
    #[test]
    fn numbers_on_the_command_line_are_refused_by_name_or_reach_the_output_check((k, value) in case()) {
        let dir = std::env::temp_dir().join(format!("riverplanet-cli-fuzz-{}", std::process::id()));
        let config = small_planet(&dir);
        let out = run(k, &value, &config, &dir.join("missing"));
        check(k, &value, &out)?;
        if out.status.code() == Some(0) {
            prop_assert!(false, "wrote into a missing folder: {:?}", OPTIONS[k]);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, failure_persistence: None, ..ProptestConfig::default() })]

    /// For real, on a small planet: what the parsers accept runs to the end and writes its output.
    #[test]
    fn accepted_numbers_run_to_the_end((k, value) in plausible_case()) {
        let dir = std::env::temp_dir().join(format!("riverplanet-cli-real-{}", std::process::id()));
        let config = small_planet(&dir);
        let (_, file, _) = output_and_limits(OPTIONS[k].0);
        let _ = std::fs::remove_file(dir.join(file));
        let _ = std::fs::remove_dir_all(dir.join(file));
        let out = run(k, &value, &config, &dir);
        check(k, &value, &out)?;
        if out.status.success() {
            prop_assert!(dir.join(file).exists(), "{:?} {} wrote nothing", OPTIONS[k], value);
        }
    }
}
