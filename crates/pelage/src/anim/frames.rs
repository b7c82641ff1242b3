//! Frame ranges as artists and farm schedulers write them: `"12"`,
//! `"1-24"`, `"1-48x2"` (every second frame), and lists of those separated
//! by commas (`"1-10,20,30-40x5"`).

use std::fmt;

/// The most frames one range may hold: a range is expanded into a list,
/// and a typo such as `1-10000000` should be an error, not minutes of work.
pub const MAX_FRAMES: usize = crate::limits::MAX_FRAMES as usize;

/// A sorted list of distinct whole frames.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameRange {
    frames: Vec<i32>,
}

/// A frame range that could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("frame range {text:?}: {message}")]
pub struct FrameRangeError {
    /// The text as given.
    pub text: String,
    /// What is wrong with it.
    pub message: String,
}

impl std::str::FromStr for FrameRange {
    type Err = FrameRangeError;

    /// [`FrameRange::parse`].
    fn from_str(text: &str) -> Result<Self, FrameRangeError> {
        Self::parse(text)
    }
}

impl FrameRange {
    /// Parses `"1-24"`, `"5"`, `"1-48x2"` or comma-separated lists of them.
    pub fn parse(text: &str) -> Result<Self, FrameRangeError> {
        let fail = |message: String| FrameRangeError {
            text: text.to_string(),
            message,
        };
        let number = |s: &str| {
            s.trim()
                .parse::<i32>()
                .map_err(|_| fail(format!("{s:?} is not a whole frame number")))
        };
        let mut frames = Vec::new();
        for item in text.split(',') {
            let item = item.trim();
            if item.is_empty() {
                return Err(fail("an empty item; write e.g. \"1-24\"".into()));
            }
            let (span, step) = match item.split_once('x') {
                Some((span, step)) => (span, number(step)?),
                None => (item, 1),
            };
            if step < 1 {
                return Err(fail(format!("step {step}: it must be at least 1")));
            }
            // A leading '-' is a negative frame, not a range.
            let dash = span
                .char_indices()
                .skip(1)
                .find(|&(_, c)| c == '-')
                .map(|(i, _)| i);
            let (first, last) = match dash {
                Some(i) => (number(&span[..i])?, number(&span[i + 1..])?),
                None => {
                    let f = number(span)?;
                    (f, f)
                }
            };
            if last < first {
                return Err(fail(format!("{first}-{last} runs backwards")));
            }
            let count = (i64::from(last) - i64::from(first)) / i64::from(step) + 1;
            if frames.len() as i64 + count > MAX_FRAMES as i64 {
                return Err(fail(format!("more than {MAX_FRAMES} frames")));
            }
            frames.extend((first..=last).step_by(step as usize));
        }
        frames.sort_unstable();
        frames.dedup();
        Ok(Self { frames })
    }

    /// A single frame.
    pub fn single(frame: i32) -> Self {
        Self {
            frames: vec![frame],
        }
    }

    /// The frames, ascending.
    pub fn frames(&self) -> &[i32] {
        &self.frames
    }

    /// The first frame.
    pub fn first(&self) -> i32 {
        self.frames[0]
    }

    /// The last frame.
    pub fn last(&self) -> i32 {
        *self.frames.last().expect("a range has a frame")
    }

    /// The number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Always false: a range holds at least one frame.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }
}

impl fmt::Display for FrameRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (first, last) = (self.first(), self.last());
        let contiguous = self.frames.len() as i64 == i64::from(last) - i64::from(first) + 1;
        match (self.frames.len(), contiguous) {
            (1, _) => write!(f, "{first}"),
            (_, true) => write!(f, "{first}-{last}"),
            _ => {
                let items: Vec<String> = self.frames.iter().map(i32::to_string).collect();
                f.write_str(&items.join(","))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_steps_and_lists_expand_in_order() {
        let r = |t: &str| FrameRange::parse(t).unwrap().frames().to_vec();
        assert_eq!(r("1-4"), [1, 2, 3, 4]);
        assert_eq!(r("7"), [7]);
        assert_eq!(r("1-9x4"), [1, 5, 9]);
        assert_eq!(r("10, 1-3,2"), [1, 2, 3, 10]);
        assert_eq!(r("-2-1"), [-2, -1, 0, 1]);
        assert_eq!(FrameRange::parse("1-24").unwrap().to_string(), "1-24");
    }

    #[test]
    fn bad_ranges_say_what_is_wrong() {
        let e = |t: &str| FrameRange::parse(t).unwrap_err().message;
        assert!(e("5-1").contains("backwards"));
        assert!(e("1-a").contains("not a whole frame"));
        assert!(e("1-10x0").contains("at least 1"));
        assert!(e("1-1000000").contains("more than"));
        assert!(e("").contains("empty"));
    }
}
