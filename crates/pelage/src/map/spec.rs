//! Maps written as text, as the command line and groom files give them:
//!
//! - a number: `0.5` (a constant);
//! - an image: `density.png`, with optional `:channel` (`luminance`, `r`,
//!   `g`, `b`, `a`), `:wrap` (`repeat`, `clamp`) and `:filter` (`bilinear`,
//!   `nearest`) suffixes in any order, e.g. `mask.exr:a:clamp:nearest`;
//! - noise: `noise` or `noise:frequency=8,octaves=4,seed=3,offset=0.5,scale=0.5,space=object`
//!   (any subset of the keys; `freq` is accepted for `frequency`);
//! - UDIM tiles: an image path holding `<UDIM>` (`fur.<UDIM>.png:r`);
//! - a per-vertex scalar of the mesh: `vertex:NAME` (`vertex:red`).

use super::{
    Channel, Filter, ImageMap, Map, MapError, MapErrorKind, NoiseMap, NoiseSpace, UDIM_TOKEN,
    UdimMap, VertexMap, Wrap,
};
use std::path::Path;

/// The image file a map spec names and the suffixes after it
/// (`("fur.png", ":r:clamp")`), for a spec of an image or of UDIM tiles;
/// `None` for a number, noise or a vertex map.
pub fn image_path_in_spec(spec: &str) -> Option<(&str, &str)> {
    let spec = spec.trim();
    if spec.is_empty()
        || spec.parse::<f32>().is_ok()
        || spec.starts_with("vertex:")
        || spec == "noise"
        || spec.starts_with("noise:")
    {
        return None;
    }
    let mut path = spec;
    let (mut channel, mut wrap, mut filter) = (false, false, false);
    while let Some((head, suffix)) = path.rsplit_once(':') {
        if !channel && Channel::parse(suffix).is_some() {
            channel = true;
        } else if !wrap && Wrap::parse(suffix).is_some() {
            wrap = true;
        } else if !filter && Filter::parse(suffix).is_some() {
            filter = true;
        } else {
            break;
        }
        path = head;
    }
    Some((path, &spec[path.len()..]))
}

impl Map {
    /// Parses a map spec; image paths are relative to the working folder.
    pub fn parse(spec: &str) -> Result<Map, MapError> {
        Self::parse_with_base(spec, None)
    }

    /// Parses a map spec; relative image paths are resolved against `base`
    /// (a groom file's folder) when given.
    pub fn parse_with_base(spec: &str, base: Option<&Path>) -> Result<Map, MapError> {
        let spec = spec.trim();
        let fail = |msg: String| MapError::new(spec, MapErrorKind::Spec(msg));
        if spec.is_empty() {
            return Err(fail(
                "an empty map spec; give a number, an image path or 'noise'".into(),
            ));
        }
        if let Ok(value) = spec.parse::<f32>() {
            if !value.is_finite() {
                return Err(fail("a constant map must be a finite number".into()));
            }
            return Ok(Map::Constant(value));
        }
        if let Some(name) = spec.strip_prefix("vertex:") {
            let name = name.trim();
            if name.is_empty() {
                return Err(fail(
                    "a per-vertex map names the attribute: vertex:NAME (vertex:red, vertex:density)"
                        .into(),
                ));
            }
            return Ok(Map::Vertex(VertexMap::new(name)));
        }
        if spec == "noise" || spec.starts_with("noise:") {
            return parse_noise(
                spec.strip_prefix("noise")
                    .unwrap_or_default()
                    .trim_start_matches(':'),
            )
            .map(Map::Noise)
            .map_err(fail);
        }

        let mut path = spec;
        let mut channel = None;
        let mut wrap = None;
        let mut filter = None;
        while let Some((head, suffix)) = path.rsplit_once(':') {
            if let (None, Some(c)) = (channel, Channel::parse(suffix)) {
                channel = Some(c);
            } else if let (None, Some(w)) = (wrap, Wrap::parse(suffix)) {
                wrap = Some(w);
            } else if let (None, Some(f)) = (filter, Filter::parse(suffix)) {
                filter = Some(f);
            } else {
                break;
            }
            path = head;
        }
        let resolve = |path: &str| match base {
            Some(dir) if Path::new(path).is_relative() => dir.join(path),
            _ => Path::new(path).to_path_buf(),
        };
        let full = resolve(path);
        if path.contains(UDIM_TOKEN) {
            return UdimMap::load(
                &full,
                channel.unwrap_or_default(),
                filter.unwrap_or_default(),
            )
            .map(Map::Udim);
        }
        // `spot.png:q`: the file is there, the suffix is not one we know.
        if let Some((head, suffix)) = path.rsplit_once(':')
            && !full.exists()
            && resolve(head).exists()
        {
            return Err(fail(format!(
                "unknown suffix \":{suffix}\"; an image map takes :CHANNEL (r, g, b, a or luminance), :WRAP (repeat or clamp) and :FILTER (bilinear or nearest)"
            )));
        }
        ImageMap::load(&full, channel.unwrap_or_default(), wrap.unwrap_or_default())
            .map(|image| Map::Image(image.with_filter(filter.unwrap_or_default())))
    }
}

fn parse_noise(params: &str) -> Result<NoiseMap, String> {
    let defaults = NoiseMap::default();
    let mut space = NoiseSpace::Auto;
    let (mut frequency, mut octaves, mut seed, mut offset, mut scale) = (
        defaults.frequency,
        defaults.octaves,
        defaults.seed,
        defaults.offset,
        defaults.scale,
    );
    for pair in params.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (key, value) = pair
            .split_once('=')
            .ok_or_else(|| format!("noise parameter {pair:?} is not key=value"))?;
        let (key, value) = (key.trim(), value.trim());
        let bad = |what: &str| format!("noise parameter {key}: cannot read {value:?} as {what}");
        let float = || {
            value
                .parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| bad("a number"))
        };
        match key {
            "frequency" | "freq" => frequency = float()?,
            "octaves" => octaves = value.parse().map_err(|_| bad("a whole number"))?,
            "seed" => seed = value.parse().map_err(|_| bad("a whole number"))?,
            "offset" => offset = float()?,
            "scale" => scale = float()?,
            "space" => space = NoiseSpace::parse(value).ok_or_else(|| bad("auto, uv or object"))?,
            _ => {
                return Err(format!(
                    "unknown noise parameter {key:?}; the parameters are frequency, octaves, seed, offset, scale, space"
                ));
            }
        }
    }
    if !(1..=16).contains(&octaves) {
        return Err(format!("noise octaves must be 1 to 16, not {octaves}"));
    }
    Ok(NoiseMap::new(frequency, octaves, seed, offset, scale).with_space(space))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_constants() {
        assert_eq!(Map::parse(" 0.25 ").unwrap(), Map::Constant(0.25));
        assert!(Map::parse("nan").is_err());
    }

    #[test]
    fn noise_spec_sets_parameters() {
        let Map::Noise(n) = Map::parse("noise:freq=8, octaves=2,seed=9").unwrap() else {
            panic!("expected noise")
        };
        assert_eq!((n.frequency, n.octaves, n.seed, n.offset), (8.0, 2, 9, 0.5));
        assert!(matches!(Map::parse("noise").unwrap(), Map::Noise(_)));
    }

    #[test]
    fn bad_noise_spec_says_what_is_wrong() {
        let err = Map::parse("noise:frequncy=3").unwrap_err().to_string();
        assert!(
            err.contains("unknown noise parameter \"frequncy\""),
            "{err}"
        );
        let err = Map::parse("noise:octaves=0").unwrap_err().to_string();
        assert!(err.contains("octaves must be 1 to 16"), "{err}");
    }

    #[test]
    fn image_spec_suffixes_choose_channel_and_wrap() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.png");
        image::RgbaImage::from_raw(1, 1, vec![255, 0, 0, 51])
            .unwrap()
            .save(&path)
            .unwrap();
        let spec = format!("{}:a:nearest:clamp", path.display());
        let Map::Image(img) = Map::parse(&spec).unwrap() else {
            panic!()
        };
        assert_eq!(img.wrap(), Wrap::Clamp);
        assert_eq!(img.filter(), Filter::Nearest);
        assert!((img.texel(0, 0) - 0.2).abs() < 1e-6);
        let Map::Image(img) = Map::parse_with_base("m.png:r", Some(dir.path())).unwrap() else {
            panic!()
        };
        assert_eq!(img.texel(0, 0), 1.0);
    }
}
