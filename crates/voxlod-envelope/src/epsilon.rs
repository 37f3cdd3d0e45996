//! How large ε is: a distance in the mesh's units, or a percentage of the diagonal of the
//! mesh's bounding box (the paper's Table 2 heuristic, §7); and regions with their own ε
//! (adaptive approximation, §6.5).
//!
//! Cost: O(V × regions) to give every vertex its ε.

use std::fmt;
use std::str::FromStr;

use glam::DVec3;
use serde::Serialize;

use super::EnvelopeError;

/// The approximation distance ε of one level.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "unit", content = "value")]
pub enum Epsilon {
    /// In the mesh's units.
    Absolute(f64),
    /// A fraction of the bounding-box diagonal (0.01 for "1%").
    DiagonalFraction(f64),
}

impl Epsilon {
    /// `percent` % of the bounding-box diagonal.
    pub fn percent(percent: f64) -> Epsilon {
        Epsilon::DiagonalFraction(percent / 100.0)
    }

    /// The distance, for a bounding box with this diagonal.
    pub fn resolve(self, diagonal: f64) -> f64 {
        match self {
            Epsilon::Absolute(e) => e,
            Epsilon::DiagonalFraction(f) => f * diagonal,
        }
    }

    /// Refuses zero, negative and non-finite values.
    pub fn check(self) -> Result<Epsilon, EnvelopeError> {
        let value = match self {
            Epsilon::Absolute(e) | Epsilon::DiagonalFraction(e) => e,
        };
        if value > 0.0 && value.is_finite() {
            Ok(self)
        } else {
            Err(EnvelopeError::InvalidEpsilon(self.to_string()))
        }
    }
}

impl fmt::Display for Epsilon {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Epsilon::Absolute(e) => write!(f, "{e}"),
            Epsilon::DiagonalFraction(x) => write!(f, "{}%", x * 100.0),
        }
    }
}

impl FromStr for Epsilon {
    type Err = EnvelopeError;
    /// `0.5` (mesh units) or `1%` (of the bounding-box diagonal); must be positive.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let text = s.trim();
        let bad = || EnvelopeError::InvalidEpsilon(format!("'{s}'"));
        let eps = match text.strip_suffix('%') {
            Some(p) => Epsilon::percent(p.trim().parse::<f64>().map_err(|_| bad())?),
            None => Epsilon::Absolute(text.parse::<f64>().map_err(|_| bad())?),
        };
        eps.check().map_err(|_| bad())
    }
}

/// A box whose vertices get the level's ε multiplied by `scale` (§6.5, adaptive approximation):
/// below 1 to keep a region finer, above 1 to let it go coarser. Where boxes overlap, the last
/// one listed wins.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegionEpsilon {
    /// Lower corner of the box, in the mesh's units.
    pub min: DVec3,
    /// Upper corner of the box, in the mesh's units.
    pub max: DVec3,
    /// The factor on the level's ε for vertices in the box.
    pub scale: f64,
}

impl Serialize for RegionEpsilon {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("RegionEpsilon", 3)?;
        st.serialize_field("min", &self.min.to_array())?;
        st.serialize_field("max", &self.max.to_array())?;
        st.serialize_field("scale", &self.scale)?;
        st.end()
    }
}

impl RegionEpsilon {
    /// Whether `p` lies in the box (its faces included).
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
}

impl FromStr for RegionEpsilon {
    type Err = String;
    /// `X0,Y0,Z0,X1,Y1,Z1:SCALE`, e.g. `0,0,0,1,1,1:0.25`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || {
            format!("region '{s}': expected X0,Y0,Z0,X1,Y1,Z1:SCALE with a positive scale and X0 <= X1, Y0 <= Y1, Z0 <= Z1")
        };
        let (corners, scale) = s.split_once(':').ok_or_else(bad)?;
        let numbers: Vec<f64> = corners
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad())?;
        let scale: f64 = scale.trim().parse().map_err(|_| bad())?;
        if numbers.len() != 6 || !(scale > 0.0 && scale.is_finite()) {
            return Err(bad());
        }
        let min = DVec3::new(numbers[0], numbers[1], numbers[2]);
        let max = DVec3::new(numbers[3], numbers[4], numbers[5]);
        if !(min.is_finite() && max.is_finite() && min.cmple(max).all()) {
            return Err(bad());
        }
        Ok(RegionEpsilon { min, max, scale })
    }
}

/// The scale of ε at each point: 1 outside every region.
pub(crate) fn region_scales(positions: &[DVec3], regions: &[RegionEpsilon]) -> Vec<f64> {
    positions
        .iter()
        .map(|&p| {
            regions
                .iter()
                .rev()
                .find(|r| r.contains(p))
                .map_or(1.0, |r| r.scale)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_distances_and_percentages() {
        assert_eq!(
            "1%".parse::<Epsilon>().unwrap(),
            Epsilon::DiagonalFraction(0.01)
        );
        assert_eq!(
            " 0.25 ".parse::<Epsilon>().unwrap(),
            Epsilon::Absolute(0.25)
        );
        assert_eq!("2.5 %".parse::<Epsilon>().unwrap().resolve(10.0), 0.25);
        for bad in ["0", "-1", "0%", "-2%", "abc", "nan", "inf", "%", ""] {
            assert!(bad.parse::<Epsilon>().is_err(), "{bad}");
        }
        assert_eq!(Epsilon::percent(1.0).to_string(), "1%");
    }

    #[test]
    fn regions_parse_and_the_last_wins() {
        let a: RegionEpsilon = "0,0,0,1,1,1:0.5".parse().unwrap();
        let b: RegionEpsilon = "0.5,0,0,2,1,1:2".parse().unwrap();
        assert!("0,0,0,1,1:0.5".parse::<RegionEpsilon>().is_err());
        assert!("1,0,0,0,1,1:0.5".parse::<RegionEpsilon>().is_err());
        assert!("0,0,0,1,1,1:0".parse::<RegionEpsilon>().is_err());
        let s = region_scales(
            &[
                DVec3::new(0.2, 0.5, 0.5),
                DVec3::new(0.7, 0.5, 0.5),
                DVec3::new(5.0, 0.5, 0.5),
            ],
            &[a, b],
        );
        assert_eq!(s, vec![0.5, 2.0, 1.0]);
    }
}
