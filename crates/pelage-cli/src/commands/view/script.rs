//! Scripted viewer sessions (`pelage view … --script ACTIONS.toml`): what a
//! person would do with the mouse, written down — orbit, drop water at a
//! point of the window, push the fur, wait, take screenshots — so tests and
//! demos drive the real window, event loop and renderer.
//!
//! ```toml
//! ui = false                         # hide the control panel (default: shown)
//!
//! [[step]]
//! wait = 10                          # frames
//! [[step]]
//! screenshot = "before.png"          # relative to the script's folder
//! [[step]]
//! drop = { at = [400, 300], radius = 0.05, clump = 0.012 }   # window pixels; a splash of clumps
//! [[step]]
//! orbit = [30, -10]                  # degrees: right, up
//! [[step]]
//! push = { from = [400, 300], to = [460, 300], frames = 10 } # drag the fur
//! [[step]]
//! show = { skin = false, guides = true, percent = 10 }       # groom views
//! [[step]]
//! time = 0.4                         # hold a skinned scene's clip (or an animated curves file) at 0.4 s
//!
//! # `pelage view fur.toml --groom`:
//! [[step]]
//! pointer = [500, 300]               # the guides the panel's brush would move there, highlighted
//! [[step]]
//! brush = { name = "comb", from = [500, 300], to = [560, 330], radius = 0.1, strength = 0.8 }
//! [[step]]
//! undo = 1                           # and redo = 1
//! [[step]]
//! save = "fur_groomed.toml"          # groom file + guides + paint layers
//! [[step]]
//! export = "shown.usdc"              # the hairs the window shows
//! [[step]]
//! fraction = 10                      # percent of the hairs grown
//! ```

use pelage::groom::GroomError;
use pelage::settings::SettingsSource;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// A script: steps run in order, one action a step.
#[derive(Debug, Clone, PartialEq)]
pub struct Script {
    /// Whether the control panel is drawn (and in screenshots).
    pub ui: bool,
    /// The steps.
    pub steps: Vec<Step>,
}

/// One thing done.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub enum Step {
    /// Draw this many frames (the simulation and drying go on).
    Wait(u32),
    /// Write what the window shows to a PNG.
    Screenshot(PathBuf),
    /// A click with the water tool: a splash of droplets where the ray
    /// through this pixel meets the skin (Silva Alg. 1).
    Drop(DropStep),
    /// Turn the camera around its target, degrees right and up.
    Orbit([f32; 2]),
    /// Move the camera in (< 1) or out (> 1).
    Zoom(f32),
    /// A drag with the push tool, from one pixel to another over frames.
    Push(PushStep),
    /// Shake the object (the scene's shake, or a default one).
    Shake(bool),
    /// Hold a skinned scene's clip at this many seconds.
    Time(f32),
    /// What a groom view draws: the panel's toggles.
    Show(ShowStep),
    /// Move the pointer to this pixel, no button held: in the groom mode
    /// the guides the panel's brush would move there are highlighted.
    Pointer([f32; 2]),
    /// A brush stroke in the groom mode (`--groom`), dabs along the
    /// pixels from `from` to `to`.
    Brush(BrushStep),
    /// Undo this many edits (`--groom`).
    Undo(u32),
    /// Redo this many edits (`--groom`).
    Redo(u32),
    /// Save the groom file, its guides and paint layers (`--groom`).
    Save(PathBuf),
    /// Write the hairs the window shows to a curves file (`--groom`).
    Export(PathBuf),
    /// Grow this percentage of the groom's hairs (`--groom`).
    Fraction(f32),
    /// Close the window.
    Quit(bool),
}

/// `brush = { name, from, to, dabs, radius, strength, … }`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BrushStep {
    /// The brush (`comb`, `length`, `cut`, `smooth`, `puff`, `clump`,
    /// `spread`, `add`, `delete`, `paint`, `part`).
    pub name: String,
    /// Where the stroke starts (window pixel).
    pub from: [f32; 2],
    /// Where it ends (default: where it starts).
    pub to: Option<[f32; 2]>,
    /// Dabs along it (default 8; dabs closer than a quarter of the radius
    /// on the skin are skipped, as a person's are).
    #[serde(default = "default_dabs")]
    pub dabs: u32,
    /// Radius in world units (default: the panel's).
    pub radius: Option<f32>,
    /// Strength (default: the panel's).
    pub strength: Option<f32>,
    /// `smooth`, `linear` or `constant`.
    pub falloff: Option<String>,
    /// X-mirror.
    pub mirror: Option<bool>,
    /// The paint brush's layer.
    pub layer: Option<String>,
    /// The paint brush's value.
    pub value: Option<f32>,
    /// The part brush's region.
    pub region: Option<u32>,
    /// Guides an `add` dab adds.
    pub count: Option<u32>,
}

/// The most dabs a scripted stroke takes: each is an edit and a
/// regrowth, so 10^8 of them ran for hours.
pub const MAX_STROKE_DABS: u32 = 10_000;

fn default_dabs() -> u32 {
    8
}

/// `drop = { at, radius, wetness }`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DropStep {
    /// Window pixel (x right, y down).
    pub at: [f32; 2],
    /// Splash radius in mask units (default: the panel's).
    pub radius: Option<f32>,
    /// Radius of each droplet, one clump (default: the panel's).
    pub clump: Option<f32>,
    /// ρ_drop (default: the panel's).
    pub wetness: Option<f32>,
}

/// `push = { from, to, frames }`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PushStep {
    /// Where the drag starts (window pixel).
    pub from: [f32; 2],
    /// Where it ends.
    pub to: [f32; 2],
    /// Over how many frames (default 10).
    #[serde(default = "default_push_frames")]
    pub frames: u32,
}

/// `show = { skin, hairs, guides, roots, percent }`: any of them.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShowStep {
    /// The mesh.
    pub skin: Option<bool>,
    /// The hairs.
    pub hairs: Option<bool>,
    /// The guides.
    pub guides: Option<bool>,
    /// The roots.
    pub roots: Option<bool>,
    /// Percentage of hairs drawn.
    pub percent: Option<f32>,
    /// Hairs coloured by the paint layer (`--groom`).
    pub layer: Option<bool>,
}

fn default_push_frames() -> u32 {
    10
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScriptFile {
    #[serde(default = "default_true")]
    ui: bool,
    #[serde(default)]
    step: Vec<Step>,
}

fn default_true() -> bool {
    true
}

impl Script {
    /// Reads a script; errors name the file, line and key. Screenshot
    /// paths are made relative to the script's folder.
    pub fn load(path: &Path) -> Result<Self, GroomError> {
        let source = SettingsSource::read(path).map_err(|e| {
            GroomError::new(
                path.to_path_buf(),
                None,
                None,
                pelage::groom::GroomErrorKind::Missing(format!("cannot read the script: {e}")),
            )
        })?;
        Self::parse(&source)
    }

    /// Parses a script's text.
    pub fn parse(source: &SettingsSource) -> Result<Self, GroomError> {
        let file: ScriptFile = source.parse_as()?;
        let folder = source.folder();
        let steps = file
            .step
            .into_iter()
            .map(|step| match step {
                Step::Screenshot(p) if p.is_relative() => Step::Screenshot(folder.join(p)),
                Step::Save(p) if p.is_relative() => Step::Save(folder.join(p)),
                Step::Export(p) if p.is_relative() => Step::Export(folder.join(p)),
                other => other,
            })
            .collect::<Vec<_>>();
        for step in &steps {
            if let Step::Brush(b) = step
                && !super::grooming::PALETTE.contains(&b.name.as_str())
            {
                return Err(GroomError::new(
                    source.path.clone(),
                    None,
                    Some("step.brush.name".into()),
                    pelage::groom::GroomErrorKind::Syntax(format!(
                        "no brush '{}': use one of {}",
                        b.name,
                        super::grooming::PALETTE.join(", ")
                    )),
                ));
            }
            if let Step::Brush(BrushStep {
                falloff: Some(f), ..
            }) = step
                && pelage::groom::brush::Falloff::parse(f).is_none()
            {
                return Err(GroomError::new(
                    source.path.clone(),
                    None,
                    Some("step.brush.falloff".into()),
                    pelage::groom::GroomErrorKind::Syntax(format!(
                        "falloff '{f}': use smooth, linear or constant"
                    )),
                ));
            }
        }
        for step in &steps {
            if let Step::Brush(b) = step {
                check_brush_values(source, b)?;
            }
        }
        for step in &steps {
            if let Step::Brush(b) = step
                && b.dabs > MAX_STROKE_DABS
            {
                return Err(GroomError::new(
                    source.path.clone(),
                    None,
                    Some("step.brush.dabs".into()),
                    pelage::groom::GroomErrorKind::OutOfRange(format!(
                        "{} dabs in one stroke: use at most {MAX_STROKE_DABS} (a stroke's dabs are regrown one by one)",
                        b.dabs
                    )),
                ));
            }
        }
        Ok(Self { ui: file.ui, steps })
    }

    /// A script that draws `frames` frames, writes `screenshot` and quits:
    /// `pelage view --screenshot OUT.png` without a script.
    pub fn screenshot_after(frames: u32, screenshot: PathBuf) -> Self {
        Self {
            ui: true,
            steps: vec![Step::Wait(frames), Step::Screenshot(screenshot)],
        }
    }
}

/// A brush step's radius, strength and layer, refused when the read
/// script is: a dab with them would be refused at its stroke, after the
/// steps before it had run.
fn check_brush_values(source: &SettingsSource, b: &BrushStep) -> Result<(), GroomError> {
    use pelage::groom::GroomErrorKind;
    let refuse = |key: &str, kind: GroomErrorKind| {
        Err(GroomError::new(
            source.path.clone(),
            None,
            Some(format!("step.brush.{key}")),
            kind,
        ))
    };
    if let Some(r) = b.radius
        && !(r.is_finite() && r > 0.0)
    {
        return refuse(
            "radius",
            GroomErrorKind::OutOfRange(format!("radius {r}: use a positive distance")),
        );
    }
    let most = pelage::groom::brush::MAX_BRUSH_STRENGTH;
    if let Some(s) = b.strength
        && !(s.is_finite() && s.abs() <= most)
    {
        return refuse(
            "strength",
            GroomErrorKind::OutOfRange(format!("strength {s}: use -{most} to {most}")),
        );
    }
    if let Some(layer) = &b.layer
        && let Err(e) = pelage::groom::brush::check_layer_name(layer)
    {
        return refuse("layer", GroomErrorKind::Brush(e));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Script, GroomError> {
        Script::parse(&SettingsSource {
            path: "shots/act.toml".into(),
            text: text.into(),
        })
    }

    #[test]
    fn every_action_reads_back() {
        let script = parse(
            r#"
ui = false
[[step]]
wait = 3
[[step]]
screenshot = "a.png"
[[step]]
drop = { at = [10, 20], radius = 0.1 }
[[step]]
orbit = [30, -5]
[[step]]
zoom = 0.5
[[step]]
push = { from = [1, 2], to = [3, 4] }
[[step]]
shake = true
[[step]]
quit = true
"#,
        )
        .unwrap();
        assert!(!script.ui);
        assert_eq!(
            script.steps,
            vec![
                Step::Wait(3),
                Step::Screenshot(PathBuf::from("shots/a.png")),
                Step::Drop(DropStep {
                    at: [10.0, 20.0],
                    radius: Some(0.1),
                    wetness: None,
                    clump: None
                }),
                Step::Orbit([30.0, -5.0]),
                Step::Zoom(0.5),
                Step::Push(PushStep {
                    from: [1.0, 2.0],
                    to: [3.0, 4.0],
                    frames: 10
                }),
                Step::Shake(true),
                Step::Quit(true),
            ]
        );
    }

    #[test]
    fn a_misspelt_action_is_an_error_at_its_line() {
        let err = parse("[[step]]\nwait = 2\n[[step]]\ndorp = { at = [1, 2] }\n")
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("shots/act.toml:4:"), "{err}");
        assert!(err.contains("dorp"), "{err}");
        let err = parse("[[step]]\ndrop = { at = [1, 2], radius = \"big\" }\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("shots/act.toml:2:"), "{err}");
    }

    #[test]
    fn a_brush_step_with_a_bad_radius_strength_or_layer_is_refused_at_its_key() {
        for (value, key) in [
            ("radius = -0.1", "radius"),
            ("radius = nan", "radius"),
            ("strength = 1e30", "strength"),
            ("layer = \"my layer\"", "layer"),
            ("layer = \"\"", "layer"),
        ] {
            let text =
                format!("[[step]]\nbrush = {{ name = \"paint\", from = [1, 2], {value} }}\n");
            let err = parse(&text).unwrap_err();
            assert_eq!(
                err.at.key.as_deref(),
                Some(&*format!("step.brush.{key}")),
                "{value}: {err}"
            );
        }
        assert!(parse("[[step]]\nbrush = { name = \"paint\", from = [1, 2], radius = 0.1, layer = \"belly_2\" }\n").is_ok());
    }

    #[test]
    fn a_stroke_of_a_hundred_million_dabs_is_refused() {
        let err = parse("[[step]]\nbrush = { name = \"comb\", from = [1, 2], dabs = 100000000 }\n")
            .unwrap_err();
        assert!(
            matches!(err.kind, pelage::groom::GroomErrorKind::OutOfRange(_)),
            "{err}"
        );
        assert_eq!(err.at.key.as_deref(), Some("step.brush.dabs"));
        assert!(
            parse("[[step]]\nbrush = { name = \"comb\", from = [1, 2], dabs = 100 }\n").is_ok()
        );
    }
}
