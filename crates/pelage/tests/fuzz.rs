//! Fuzzing every parser on stable Rust: each harness mutates the seed
//! files in `tests/hostile/fuzz/PARSER/` (structured mutations, see
//! [`Mutator`]) and feeds them to the parser, which must return (an error
//! or a value) and never panic.
//!
//! ```text
//! cargo test --release -p pelage --test fuzz -- --ignored --nocapture
//! PELAGE_FUZZ_SECONDS=600 cargo test --release -p pelage --test fuzz -- --ignored fuzz_obj
//! ```
//!
//! The budget is `PELAGE_FUZZ_SECONDS` per parser (default 10) or
//! `PELAGE_FUZZ_EXECS` executions; `PELAGE_FUZZ_SEED` varies the run. Each
//! harness prints its executions and executions per second. An input that
//! panics is saved under `target/fuzz-crashes/PARSER/` and fails the test;
//! once fixed, copy it into the parser's seed folder so every later run
//! starts from it.
//!
//! An input that makes a parser allocate without bound cannot be caught:
//! the process is limited to 8 GB of address space, so the allocation
//! fails and the process aborts. With `PELAGE_FUZZ_TRACE=1` every input is
//! written to `target/fuzz-crashes/PARSER/in-flight` before it is parsed,
//! so the one that aborted is there afterwards (slower: a file write an
//! input).
//!
//! There is no coverage feedback (that needs a nightly compiler); the
//! mutations are structured instead: numbers replaced by the values that
//! break parsers (0, −1, 2³² + 1, 1e39, NaN), lines and tokens of the
//! format duplicated, dropped and swapped, binary fields overwritten with
//! extreme integers, files truncated and spliced together.

use pelage::Mesh;
use pelage::io::HairFile;
use pelage::map::{Channel, ImageMap, Wrap};
use pelage::mesh::MeshFormat;
use pelage::settings::SettingsSource;
use pelage::shell::ShellScene;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Where the seed files are.
fn corpus_folder(parser: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/hostile/fuzz")
        .join(parser)
}

/// A small, fast, deterministic random number generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `0..n` (`n > 0`).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Numbers that break parsers: zero, negatives, the edges of integer
/// types, floats beyond f32, non-finite values, and malformed ones.
const NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "255",
    "256",
    "65536",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967297",
    "-2147483649",
    "18446744073709551616",
    "99999999999999999999999",
    "1e39",
    "-1e39",
    "1e-45",
    "3.4028236e38",
    "nan",
    "inf",
    "-inf",
    "-0",
    "0x10",
    "1.",
    ".",
    "1e",
    "--1",
];

/// Integers to write into binary fields (little and big endian).
const INTEGERS: &[u64] = &[
    0,
    1,
    0x7f,
    0x80,
    0xff,
    0x7fff,
    0xffff,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
    0x1_0000_0001,
    0x7fff_ffff_ffff_ffff,
    u64::MAX,
];

/// Mutates seed files; `tokens` are pieces of the format worth inserting
/// (keywords, brackets, headers).
struct Mutator<'a> {
    seeds: &'a [Vec<u8>],
    tokens: &'a [&'a str],
    text: bool,
    rng: Rng,
}

impl Mutator<'_> {
    /// A new input: a seed with one to six mutations.
    fn input(&mut self) -> Vec<u8> {
        let mut data = self.seeds[self.rng.below(self.seeds.len())].clone();
        for _ in 0..1 + self.rng.below(6) {
            self.mutate(&mut data);
        }
        data
    }

    fn mutate(&mut self, data: &mut Vec<u8>) {
        let kinds = if self.text { 12 } else { 8 };
        match self.rng.below(kinds) {
            0 if !data.is_empty() => {
                let i = self.rng.below(data.len());
                data[i] ^= 1 << self.rng.below(8);
            }
            1 if !data.is_empty() => {
                let i = self.rng.below(data.len());
                data[i] = self.rng.next() as u8;
            }
            2 => {
                let at = self.rng.below(data.len() + 1);
                let n = 1 + self.rng.below(8);
                let bytes: Vec<u8> = (0..n).map(|_| self.rng.next() as u8).collect();
                data.splice(at..at, bytes);
            }
            3 if !data.is_empty() => {
                let a = self.rng.below(data.len());
                let b = (a + 1 + self.rng.below(64)).min(data.len());
                data.drain(a..b);
            }
            4 if !data.is_empty() => {
                let a = self.rng.below(data.len());
                let b = (a + 1 + self.rng.below(256)).min(data.len());
                let copy = data[a..b].to_vec();
                let at = self.rng.below(data.len() + 1);
                data.splice(at..at, copy);
            }
            5 if data.len() >= 8 => {
                let value = INTEGERS[self.rng.below(INTEGERS.len())];
                let width = [1, 2, 4, 8][self.rng.below(4)];
                let bytes = if self.rng.below(2) == 0 {
                    value.to_le_bytes()
                } else {
                    value.to_be_bytes()
                };
                let at = self.rng.below(data.len() - width + 1);
                let from = if self.rng.below(2) == 0 { 0 } else { 8 - width };
                data[at..at + width].copy_from_slice(&bytes[from..from + width]);
            }
            6 if !data.is_empty() => {
                let at = self.rng.below(data.len());
                data.truncate(at);
            }
            7 => {
                // Splice: this input's head, another seed's tail.
                let other = &self.seeds[self.rng.below(self.seeds.len())];
                let at = self.rng.below(data.len() + 1);
                let from = self.rng.below(other.len() + 1);
                data.truncate(at);
                data.extend_from_slice(&other[from..]);
            }
            8 => self.replace_number(data),
            9 => self.edit_lines(data),
            10 | 11 => {
                let token = self.tokens[self.rng.below(self.tokens.len())];
                let at = self.char_boundary(data);
                data.splice(at..at, token.bytes());
            }
            _ => {}
        }
    }

    /// A position at a line start or after a space, so text stays text.
    fn char_boundary(&mut self, data: &[u8]) -> usize {
        let candidates: Vec<usize> = std::iter::once(0)
            .chain(
                data.iter()
                    .enumerate()
                    .filter(|(_, b)| matches!(b, b'\n' | b' ' | b'=' | b','))
                    .map(|(i, _)| i + 1),
            )
            .collect();
        candidates[self.rng.below(candidates.len())]
    }

    /// Replaces one number of the text with one of [`NUMBERS`].
    fn replace_number(&mut self, data: &mut Vec<u8>) {
        let mut spans = Vec::new();
        let mut i = 0;
        while i < data.len() {
            if data[i].is_ascii_digit() {
                let start = i;
                while i < data.len() && (data[i].is_ascii_digit() || b".eE+-".contains(&data[i])) {
                    i += 1;
                }
                spans.push(start..i);
            }
            i += 1;
        }
        if spans.is_empty() {
            return;
        }
        let span = spans[self.rng.below(spans.len())].clone();
        let number = NUMBERS[self.rng.below(NUMBERS.len())];
        data.splice(span, number.bytes());
    }

    /// Duplicates, drops or swaps whole lines.
    fn edit_lines(&mut self, data: &mut Vec<u8>) {
        let mut lines: Vec<Vec<u8>> = data.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
        let n = lines.len();
        let (a, b) = (self.rng.below(n), self.rng.below(n));
        match self.rng.below(3) {
            0 => {
                let copy = lines[a].clone();
                for _ in 0..1 + self.rng.below(3) {
                    lines.insert(b, copy.clone());
                }
            }
            1 if n > 1 => {
                lines.remove(a);
            }
            _ => lines.swap(a, b),
        }
        *data = lines.join(&b'\n');
    }
}

thread_local! {
    /// The message of the last panic in a parser on this thread (the hook
    /// keeps those quiet).
    static LAST_PANIC: RefCell<String> = const { RefCell::new(String::new()) };
    /// Whether this thread is inside a parser now.
    static IN_PARSER: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `parse` on mutated seeds of `parser` for the budget; saves and
/// reports every input that panics.
fn fuzz(parser: &str, tokens: &[&str], text: bool, parse: impl Fn(&[u8])) {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        // An unbounded allocation then fails here rather than bringing the
        // machine's out-of-memory killer.
        #[cfg(unix)]
        {
            let limit = libc::rlimit {
                rlim_cur: 8 << 30,
                rlim_max: 8 << 30,
            };
            // SAFETY: setrlimit with a valid struct.
            unsafe { libc::setrlimit(libc::RLIMIT_AS, &limit) };
        }
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if IN_PARSER.with(|p| p.get()) {
                LAST_PANIC.with(|p| *p.borrow_mut() = info.to_string());
            } else {
                default(info);
            }
        }))
    });
    let mut seeds = Vec::new();
    let mut names: Vec<_> = std::fs::read_dir(corpus_folder(parser))
        .unwrap_or_else(|e| panic!("the seed folder of {parser}: {e}"))
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    for path in &names {
        seeds.push(std::fs::read(path).unwrap());
    }
    assert!(!seeds.is_empty(), "no seed files for {parser}");
    let env = |key: &str| std::env::var(key).ok().and_then(|v| v.parse::<u64>().ok());
    let seconds = env("PELAGE_FUZZ_SECONDS").unwrap_or(10);
    let max_execs = env("PELAGE_FUZZ_EXECS").unwrap_or(u64::MAX);
    let seed = env("PELAGE_FUZZ_SEED").unwrap_or(1);
    let mut mutator = Mutator {
        seeds: &seeds,
        tokens,
        text,
        rng: Rng(0x9E37_79B9_7F4A_7C15 ^ seed.wrapping_mul(0x1000_0000_01B3) ^ parser.len() as u64),
    };
    let crash_folder = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../target/fuzz-crashes")
        .join(parser);
    let trace = std::env::var_os("PELAGE_FUZZ_TRACE").is_some();
    if trace {
        std::fs::create_dir_all(&crash_folder).unwrap();
    }
    let start = Instant::now();
    let budget = Duration::from_secs(seconds);
    let (mut execs, mut crashes, mut slowest) = (0u64, Vec::new(), Duration::ZERO);
    // Seeds first, as they are: they must parse without a panic too.
    let mut pending: Vec<Vec<u8>> = seeds.clone();
    while execs < max_execs && (start.elapsed() < budget || !pending.is_empty()) {
        let input = pending.pop().unwrap_or_else(|| mutator.input());
        if trace {
            std::fs::write(crash_folder.join("in-flight"), &input).unwrap();
        }
        let began = Instant::now();
        IN_PARSER.with(|p| p.set(true));
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| parse(&input)));
        IN_PARSER.with(|p| p.set(false));
        slowest = slowest.max(began.elapsed());
        execs += 1;
        if result.is_err() {
            let message = LAST_PANIC.with(|p| p.borrow().clone());
            std::fs::create_dir_all(&crash_folder).unwrap();
            let file = crash_folder.join(format!("crash-{:016x}", hash(&input)));
            std::fs::write(&file, &input).unwrap();
            crashes.push(format!("{}: {message}", file.display()));
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    println!(
        "fuzz {parser}: {execs} executions in {elapsed:.1} s ({:.0}/s), slowest {:.1} ms, {} crashes",
        execs as f64 / elapsed,
        slowest.as_secs_f64() * 1e3,
        crashes.len()
    );
    assert!(
        crashes.is_empty(),
        "{parser}: {} inputs panicked:\n{}",
        crashes.len(),
        crashes.join("\n")
    );
}

/// FNV-1a, for crash file names.
fn hash(data: &[u8]) -> u64 {
    data.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    })
}

#[test]
#[ignore = "fuzzing: run with --ignored (PELAGE_FUZZ_SECONDS sets the budget)"]
fn fuzz_obj() {
    let tokens = [
        "v ",
        "vt ",
        "vn ",
        "f ",
        "f 1 2 3\n",
        "f -1 -2 -3\n",
        "/",
        "//",
        "\n",
        "#",
        "\u{feff}",
        "g x\n",
        "o\n",
        "1e39 ",
        "nan ",
    ];
    fuzz("obj", &tokens, true, |data| {
        let _ = Mesh::from_bytes("fuzz.obj", data, MeshFormat::Obj);
    });
}

#[test]
#[ignore = "fuzzing: run with --ignored (PELAGE_FUZZ_SECONDS sets the budget)"]
fn fuzz_ply() {
    let tokens = [
        "element vertex ",
        "element face ",
        "property float x\n",
        "property list uchar int vertex_indices\n",
        "property double s\n",
        "format binary_big_endian 1.0\n",
        "format ascii 1.0\n",
        "end_header\n",
        "comment \n",
        "obj_info\n",
        " 4294967295",
        " -1",
        "\n",
    ];
    fuzz("ply", &tokens, false, |data| {
        let _ = Mesh::from_bytes("fuzz.ply", data, MeshFormat::Ply);
    });
}

#[test]
#[ignore = "fuzzing: run with --ignored (PELAGE_FUZZ_SECONDS sets the budget)"]
fn fuzz_gltf() {
    let tokens = [
        "\"children\":[0],",
        "\"children\":[1,1],",
        "\"mesh\":0,",
        "\"POSITION\":9,",
        "\"indices\":0,",
        "\"byteStride\":4,",
        "\"count\":4294967295,",
        "\"mode\":5,",
        "\"skin\":0,",
        "\"matrix\":[0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0],",
        "{",
        "}",
        "[",
        "]",
        ",",
        "\"uri\":\"data:application/octet-stream;base64,AAAA\",",
    ];
    fuzz("gltf", &tokens, true, |data| {
        let _ = Mesh::from_bytes("fuzz.gltf", data, MeshFormat::Gltf);
    });
}

#[test]
#[ignore = "fuzzing: run with --ignored (PELAGE_FUZZ_SECONDS sets the budget)"]
fn fuzz_usda() {
    let tokens = [
        "def BasisCurves \"c\" {\n",
        "def Mesh \"m\" {\n",
        "}\n",
        "int[] curveVertexCounts = [",
        "point3f[] points = [",
        "(",
        ")",
        "[",
        "]",
        "float[] widths.timeSamples = { 1: [1] }\n",
        "uniform token type = \"cubic\"\n",
        "#usda 1.0\n",
        "\"",
        ", ",
    ];
    fuzz("usda", &tokens, true, |data| {
        let _ = pelage::io::usd_curves_from_bytes(data, Path::new("fuzz.usda"));
        let _ = Mesh::from_bytes("fuzz.usda", data, MeshFormat::Usd);
    });
}

#[test]
#[ignore = "fuzzing: run with --ignored (PELAGE_FUZZ_SECONDS sets the budget)"]
fn fuzz_usdc() {
    fuzz("usdc", &[], false, |data| {
        let _ = pelage::io::usd_curves_from_bytes(data, Path::new("fuzz.usdc"));
        let _ = Mesh::from_bytes("fuzz.usdc", data, MeshFormat::Usd);
    });
}

#[test]
#[ignore = "fuzzing: run with --ignored (PELAGE_FUZZ_SECONDS sets the budget)"]
fn fuzz_abc() {
    fuzz("abc", &[], false, |data| {
        let _ = pelage::io::abc_curves_from_bytes(data, Path::new("fuzz.abc"), None);
        let _ = pelage::io::abc_curves_from_bytes(data, Path::new("fuzz.abc"), Some(0.5));
    });
}

#[test]
#[ignore = "fuzzing: run with --ignored (PELAGE_FUZZ_SECONDS sets the budget)"]
fn fuzz_hair() {
    fuzz("hair", &[], false, |data| {
        let _ = HairFile::parse(data, Path::new("fuzz.hair"));
    });
}

#[test]
#[ignore = "fuzzing: run with --ignored (PELAGE_FUZZ_SECONDS sets the budget)"]
fn fuzz_groom_toml() {
    let tokens = [
        "[[ops]]\n",
        "[ops]\n",
        "[roots]\n",
        "[finish]\n",
        "[animation]\n",
        "count = ",
        "points = ",
        "clump = { count = 1 }\n",
        "twist = { angle = 1e30 }\n",
        "flyaways = { spread = 1, fraction = 2 }\n",
        "strands = { count = 4294967297 }\n",
        "subdivide = 20\n",
        "= nan\n",
        "= inf\n",
        "\"",
        "{",
        "}",
        "[",
        "]",
        "\u{feff}",
        "frames = \"1-100000000\"\n",
        "[look]\n",
        "melanin = ",
        "tint = [1, 2]\n",
        "jitter = 2\n",
        "[output]\nguides = true\n",
        "mode = \"simulate\"\n",
        "[simulation]\n",
        "substeps = 4294967297\n",
        "gravity = [1e39, 0, 0]\n",
        "cache = \"\"\n",
        "preroll = -1\n",
        "outside_skin = true\n",
        "skin_gap = -1\n",
    ];
    fuzz("groom", &tokens, true, |data| {
        if let Ok(text) = std::str::from_utf8(data) {
            let source = SettingsSource {
                path: "fuzz.toml".into(),
                text: text.to_string(),
            };
            let _ = source.check_groom();
        }
    });
}

#[test]
#[ignore = "fuzzing: run with --ignored (PELAGE_FUZZ_SECONDS sets the budget)"]
fn fuzz_shells_toml() {
    let tokens = [
        "[[droplets]]\n",
        "[droplets]\n",
        "[dynamics]\n",
        "[camera]\n",
        "[dynamics.wind]\n",
        "layers = ",
        "frames = ",
        "substeps = ",
        "mass = 0\n",
        "= nan\n",
        "\"",
        "{",
        "}",
        "[",
        "]",
        "count = 100000000000\n",
        "radius = [0.1, -1]\n",
    ];
    fuzz("shells", &tokens, true, |data| {
        if let Ok(text) = std::str::from_utf8(data) {
            let source = SettingsSource {
                path: "fuzz.toml".into(),
                text: text.to_string(),
            };
            let _ = ShellScene::check_text(&source);
        }
    });
}

#[test]
#[ignore = "fuzzing: run with --ignored (PELAGE_FUZZ_SECONDS sets the budget)"]
fn fuzz_image_maps() {
    fuzz("image", &[], false, |data| {
        let _ = ImageMap::from_bytes("fuzz.png", data, Channel::R, Wrap::Repeat);
    });
}
