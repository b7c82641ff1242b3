//! Value parsers shared by the subcommands' flags: counts under pelage's
//! ceilings ([`pelage::limits`]), finite numbers, sizes and vectors. A bad
//! value is refused by clap before any work starts, with the flag named.

use pelage::limits;

/// A whole number in `1..=max`, with the ceiling named when it is passed.
pub fn count_up_to<T: TryFrom<u64>>(
    max: u64,
    what: &'static str,
) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static {
    move |s| {
        let v: u64 = s
            .trim()
            .replace('_', "")
            .parse()
            .map_err(|_| format!("{s:?} is not a whole number"))?;
        limits::check_count(v, max, false, what).map_err(|e| e.to_string())?;
        T::try_from(v).map_err(|_| format!("{v} {what} is too many for this machine"))
    }
}

/// A finite number.
pub fn finite(s: &str) -> Result<f32, String> {
    let v: f32 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{s} is not a finite number"))
    }
}

/// A finite number above 0.
pub fn positive(s: &str) -> Result<f64, String> {
    let v = finite(s)? as f64;
    if v > 0.0 {
        // Parsed again as f64: `finite` went through f32 for its check.
        Ok(s.trim().parse().unwrap_or(v))
    } else {
        Err(format!("{s}: use a number above 0"))
    }
}

/// A vertical field of view in degrees, above 0 and below 180.
pub fn field_of_view(s: &str) -> Result<f32, String> {
    let v = finite(s)?;
    if v > 0.0 && v < 180.0 {
        Ok(v)
    } else {
        Err(format!("{s}°: use more than 0 and less than 180"))
    }
}

/// `WIDTHxHEIGHT`, each side 1 to [`limits::MAX_IMAGE_SIDE`].
pub fn size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?} is not WIDTHxHEIGHT, e.g. 1280x720"))?;
    let parse = |v: &str| {
        let n = v
            .trim()
            .parse::<u32>()
            .map_err(|_| format!("{v:?} is not a whole number"))?;
        if n == 0 || u64::from(n) > limits::MAX_IMAGE_SIDE {
            return Err(format!(
                "{n} pixels: use 1 to {} a side",
                limits::MAX_IMAGE_SIDE
            ));
        }
        Ok(n)
    };
    Ok((parse(w)?, parse(h)?))
}

/// `X,Y,Z`, three finite numbers.
pub fn vec3(s: &str) -> Result<[f32; 3], String> {
    let parts: Vec<f32> = s.split(',').map(finite).collect::<Result<_, _>>()?;
    <[f32; 3]>::try_from(parts).map_err(|_| format!("{s:?} is not X,Y,Z"))
}

/// Worker threads: at least 1. More than the machine runs at once gain
/// nothing (the output is the same for any number), so
/// [`worker_threads`] caps them.
pub fn threads(s: &str) -> Result<usize, String> {
    count_up_to::<usize>(1 << 20, "threads")(s)
}

/// `wanted` worker threads, capped at what the machine runs at once; the
/// second value says whether it was capped.
pub fn worker_threads(wanted: usize) -> (usize, bool) {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if wanted > cores {
        (cores, true)
    } else {
        (wanted, false)
    }
}

/// A finite number above 0, single precision.
pub fn positive_f32(s: &str) -> Result<f32, String> {
    positive(s).map(|v| v as f32)
}
