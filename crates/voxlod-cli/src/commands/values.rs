//! The values of numeric flags, parsed and checked by clap.
//!
//! Every flag that takes a number or a comma-separated list of numbers is typed here, and takes
//! its value with `allow_hyphen_values`, so that a negative value reads as written:
//! `--iso -0.5`, `--threshold -500` (Hounsfield units), `--origin -128,-128,0`, `--iso -.5`.
//! clap's own `allow_negative_numbers` is not enough: its number test refuses lists
//! (`-128,0,0`) and a leading dot (`-.5`). Taking any hyphenated word as the value is safe only
//! because the value must then parse as numbers: a flag written where a value is missing
//! (`--origin --json`) is refused as "not a number" instead of being swallowed.
//! NaN and infinities are refused here too, so no command sees them.

use std::str::FromStr;

/// A number a flag can take.
pub trait FlagNumber: FromStr + Copy + Send + Sync + 'static {
    /// What the flag takes, for the error: "a number", "a whole number of 0 or more".
    const KIND: &'static str;
    fn is_finite_number(self) -> bool;
}

macro_rules! flag_number {
    ($kind:literal, $finite:expr, $($t:ty),*) => {$(
        impl FlagNumber for $t {
            const KIND: &'static str = $kind;
            fn is_finite_number(self) -> bool {
                $finite(self)
            }
        }
    )*};
}

flag_number!("a number", f64::is_finite, f64);
flag_number!("a number", f32::is_finite, f32);
flag_number!("a whole number of 0 or more", |_| true, usize, u32, u64);
flag_number!("a whole number", |_| true, i64);

/// One finite number.
pub fn number<T: FlagNumber>(text: &str) -> Result<T, String> {
    let t = text.trim();
    let value: T = t.parse().map_err(|_| not_a_number(t, T::KIND))?;
    if !value.is_finite_number() {
        return Err(format!("'{t}' is not a finite number"));
    }
    Ok(value)
}

/// `A,B,C`: exactly `N` finite numbers.
pub fn numbers<T: FlagNumber, const N: usize>(text: &str) -> Result<[T; N], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() == 1 && N > 1 {
        // A single word: say what is wrong with it (a flag where the value was left out).
        number::<T>(parts[0])?;
    }
    if parts.len() != N {
        return Err(format!(
            "takes {N} comma-separated numbers, got {} in '{text}'",
            parts.len()
        ));
    }
    let mut out = Vec::with_capacity(N);
    for p in parts {
        out.push(number::<T>(p)?);
    }
    Ok(out.try_into().unwrap_or_else(|_| unreachable!("{N} parts")))
}

/// The message for a word that is not `kind` ("a number"), with a hint when it is a flag (the
/// value was left out before it).
fn not_a_number(text: &str, kind: &str) -> String {
    let is_flag = text.starts_with("--")
        || (text.len() == 2 && text.starts_with('-') && !text.as_bytes()[1].is_ascii_digit());
    if is_flag {
        format!("'{text}' is a flag, not {kind}: the value is missing")
    } else {
        format!("'{text}' is not {kind}")
    }
}

/// An image size `WxH` in pixels, each side 1 to 16384.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageSize {
    pub width: u32,
    pub height: u32,
}

impl ImageSize {
    pub const MAX_SIDE: u32 = 16384;
}

/// Parses `WxH`.
pub fn image_size(text: &str) -> Result<ImageSize, String> {
    let bad = || format!("takes WIDTHxHEIGHT in pixels (e.g. 800x600), got '{text}'");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let side = |s: &str| -> Result<u32, String> {
        let v: i64 = s.trim().parse().map_err(|_| bad())?;
        if !(1..=ImageSize::MAX_SIDE as i64).contains(&v) {
            return Err(format!(
                "'{text}': both sides must be between 1 and {} pixels",
                ImageSize::MAX_SIDE
            ));
        }
        Ok(v as u32)
    };
    Ok(ImageSize {
        width: side(w)?,
        height: side(h)?,
    })
}

/// A library failure in the command line's words, keeping the exit status of its class: an
/// option of a facade call out of range becomes `--FLAG VALUE: problem`, and an option named in
/// backticks in any other usage or input message becomes `--FLAG`. `flags` pairs an option's
/// field name with its flag where they differ (`("radius_voxels", "--radius")`); any other
/// option is its field name with `--` in front and hyphens for underscores. Other failures
/// stay as the library words them.
pub fn in_flags(e: voxlod::Error, flags: &[(&str, &str)]) -> super::CliError {
    use super::CliError;
    let flag = |option: &str| match flags.iter().find(|(o, _)| *o == option) {
        Some((_, flag)) => flag.to_string(),
        None => format!("--{}", option.replace('_', "-")),
    };
    if let voxlod::Error::InvalidOption(o) = e.root() {
        return CliError::usage(format!("{} {}: {}", flag(o.option), o.value, o.problem));
    }
    let text = e.to_string();
    let class = e.class();
    if !text.contains('`') {
        return CliError::Library(e);
    }
    let mut words = String::new();
    for (i, piece) in text.split('`').enumerate() {
        let option = i % 2 == 1 && piece.chars().all(|c| c.is_ascii_lowercase() || c == '_');
        match (i % 2 == 1, option) {
            (true, true) => words.push_str(&flag(piece)),
            (true, false) => words.extend(['`'].into_iter().chain(piece.chars()).chain(['`'])),
            (false, _) => words.push_str(piece),
        }
    }
    match class {
        voxlod::ErrorClass::Usage => CliError::usage(words),
        voxlod::ErrorClass::BadInput => CliError::msg(words),
        _ => CliError::Library(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn library_options_are_named_as_flags() {
        let e = voxlod::InvalidOption::new("radius_voxels", 0, "must be positive");
        let e = voxlod::Error::from(e).context("bunny.obj");
        let text = in_flags(e, &[("radius_voxels", "--radius")]).to_string();
        assert_eq!(text, "--radius 0: must be positive");
        let e = in_flags(voxlod::PyramidError::NeedsSolid.into(), &[]);
        assert!(
            e.to_string().ends_with("a volume with a --threshold"),
            "{e}"
        );
        assert_eq!(e.exit_code(), 2);
    }

    #[test]
    fn negative_and_list_values_parse_as_written() {
        assert_eq!(number::<f64>("-0.5"), Ok(-0.5));
        assert_eq!(number::<f32>("-.5"), Ok(-0.5));
        assert_eq!(number::<f32>(" -500 "), Ok(-500.0));
        assert_eq!(
            numbers::<f64, 3>("-128,-128.5,0"),
            Ok([-128.0, -128.5, 0.0])
        );
        assert_eq!(numbers::<usize, 3>("4, 5,6"), Ok([4, 5, 6]));
    }

    #[test]
    fn non_numbers_and_flags_are_refused_with_the_reason() {
        assert_eq!(
            number::<f64>("nan"),
            Err("'nan' is not a finite number".into())
        );
        assert_eq!(
            number::<f64>("-inf"),
            Err("'-inf' is not a finite number".into())
        );
        assert_eq!(
            number::<f64>("--json"),
            Err("'--json' is a flag, not a number: the value is missing".into())
        );
        assert_eq!(
            number::<f32>("-o"),
            Err("'-o' is a flag, not a number: the value is missing".into())
        );
        assert_eq!(number::<f32>("x"), Err("'x' is not a number".into()));
        assert_eq!(
            number::<u32>("-3"),
            Err("'-3' is not a whole number of 0 or more".into())
        );
        assert_eq!(
            numbers::<f64, 3>("--json"),
            Err("'--json' is a flag, not a number: the value is missing".into())
        );
        assert_eq!(
            numbers::<f64, 3>("1,2"),
            Err("takes 3 comma-separated numbers, got 2 in '1,2'".into())
        );
        assert_eq!(
            numbers::<usize, 3>("4,-4,4"),
            Err("'-4' is not a whole number of 0 or more".into())
        );
    }

    #[test]
    fn image_sizes() {
        assert_eq!(
            image_size("800x600"),
            Ok(ImageSize {
                width: 800,
                height: 600
            })
        );
        assert!(image_size("0x10")
            .unwrap_err()
            .contains("between 1 and 16384"));
        assert!(image_size("-5x10")
            .unwrap_err()
            .contains("between 1 and 16384"));
        assert!(image_size("800").unwrap_err().contains("WIDTHxHEIGHT"));
    }
}
