//! Cross-sections of a rod as functions of the arc length `s`.
//!
//! A [`Section`] gives, at every `s` in `[0, L]`, the [`SectionProperties`]: area `A` (m²),
//! second moments of area `Ix`, `Iy` about the body x and y axes (m⁴), torsion constant `J`
//! (m⁴), an outer radius (m, used by tendon routings proportional to the radius) and its rate
//! `dR/ds`. Shapes: solid circle, linearly tapered solid circle, tube, tables of `(s, A, Ix, Iy,
//! J)` (piecewise linear), and user functions.

use std::f64::consts::PI;
use std::fmt;
use std::sync::Arc;

use crate::error::{check_positive, Error, Result};

/// Geometric properties of one cross-section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionProperties {
    /// Area `A` (m²).
    pub area: f64,
    /// Second moment of area about the body x axis, `Ix` (m⁴): bending about x.
    pub ix: f64,
    /// Second moment of area about the body y axis, `Iy` (m⁴): bending about y.
    pub iy: f64,
    /// Torsion constant `J` (m⁴); the polar moment `Ix + Iy` for circles and tubes.
    pub j: f64,
    /// Outer radius `R` (m); for tables, the radius of the circle of area `A`.
    pub radius: f64,
    /// Rate `dR/ds` of the outer radius (dimensionless).
    pub radius_rate: f64,
}

impl SectionProperties {
    /// Properties of a solid circle of radius `r` (m), with `dR/ds = rate`.
    pub fn circle(r: f64, rate: f64) -> Self {
        let i = PI * r.powi(4) / 4.0;
        Self {
            area: PI * r * r,
            ix: i,
            iy: i,
            j: 2.0 * i,
            radius: r,
            radius_rate: rate,
        }
    }

    /// Properties of a tube with outer radius `ro` and inner radius `ri` (m).
    pub fn tube(ro: f64, ri: f64) -> Self {
        let i = PI * (ro.powi(4) - ri.powi(4)) / 4.0;
        Self {
            area: PI * (ro * ro - ri * ri),
            ix: i,
            iy: i,
            j: 2.0 * i,
            radius: ro,
            radius_rate: 0.0,
        }
    }

    /// Checks that every property is finite and `A, Ix, Iy, J, R > 0`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `"{name}.area"` etc. otherwise.
    pub fn validated(self, name: &str) -> Result<Self> {
        check_positive(&format!("{name}.area"), self.area, "m^2")?;
        check_positive(&format!("{name}.ix"), self.ix, "m^4")?;
        check_positive(&format!("{name}.iy"), self.iy, "m^4")?;
        check_positive(&format!("{name}.j"), self.j, "m^4")?;
        check_positive(&format!("{name}.radius"), self.radius, "m")?;
        if !self.radius_rate.is_finite() {
            return Err(Error::invalid(
                format!("{name}.radius_rate"),
                self.radius_rate,
                "finite",
            ));
        }
        Ok(self)
    }
}

/// A user function `s (m) -> SectionProperties`; it must be thread-safe.
pub type SectionFn = Arc<dyn Fn(f64) -> SectionProperties + Send + Sync>;

#[derive(Clone)]
enum Kind {
    Circular {
        radius: f64,
    },
    Tapered {
        base_radius: f64,
        tip_radius: f64,
    },
    Tube {
        outer_radius: f64,
        inner_radius: f64,
    },
    Table {
        s: Vec<f64>,
        props: Vec<SectionProperties>,
    },
    Function(SectionFn),
}

/// A rod's cross-section along its length (immutable, validated on construction).
#[derive(Clone)]
pub struct Section {
    kind: Kind,
}

impl fmt::Debug for Section {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.kind {
            Kind::Circular { radius } => write!(f, "CircularSection(radius={radius})"),
            Kind::Tapered {
                base_radius,
                tip_radius,
            } => write!(
                f,
                "TaperedCircularSection(base_radius={base_radius}, tip_radius={tip_radius})"
            ),
            Kind::Tube {
                outer_radius,
                inner_radius,
            } => write!(
                f,
                "TubeSection(outer_radius={outer_radius}, inner_radius={inner_radius})"
            ),
            Kind::Table { s, .. } => write!(f, "TableSection({} rows)", s.len()),
            Kind::Function(_) => write!(f, "FunctionSection(<fn>)"),
        }
    }
}

impl Section {
    /// Solid circle of constant `radius` (m) (`CircularSection(radius)` in Python).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `radius` unless finite and > 0.
    pub fn circular(radius: f64) -> Result<Self> {
        check_positive("radius", radius, "m")?;
        Ok(Self {
            kind: Kind::Circular { radius },
        })
    }

    /// Solid circle whose radius varies linearly from `base_radius` at `s = 0` to `tip_radius`
    /// at `s = L` (m) (`TaperedCircularSection(base_radius, tip_radius)`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the radius that is not finite and > 0.
    pub fn tapered_circular(base_radius: f64, tip_radius: f64) -> Result<Self> {
        check_positive("base_radius", base_radius, "m")?;
        check_positive("tip_radius", tip_radius, "m")?;
        Ok(Self {
            kind: Kind::Tapered {
                base_radius,
                tip_radius,
            },
        })
    }

    /// Circular tube (m) (`TubeSection(outer_radius, inner_radius)`); `inner_radius = 0` is a
    /// solid circle.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `outer_radius` unless finite and > 0, or
    /// `inner_radius` unless finite, >= 0 and < `outer_radius`.
    pub fn tube(outer_radius: f64, inner_radius: f64) -> Result<Self> {
        check_positive("outer_radius", outer_radius, "m")?;
        if !(inner_radius.is_finite() && inner_radius >= 0.0 && inner_radius < outer_radius) {
            return Err(Error::invalid(
                "inner_radius",
                inner_radius,
                format!("finite, >= 0 and < outer_radius = {outer_radius} m"),
            ));
        }
        Ok(Self {
            kind: Kind::Tube {
                outer_radius,
                inner_radius,
            },
        })
    }

    /// Tabulated section: at the strictly increasing arc lengths `s` (m) the values `area`
    /// (m²), `ix`, `iy`, `j` (m⁴); linear interpolation between rows, constant extrapolation
    /// beyond the ends. The radius used by radius-proportional tendon routings is that of the
    /// circle of the same area, `sqrt(A / pi)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if the columns differ in length, have fewer than 2 rows,
    /// `s` is not finite and strictly increasing, or any value is not finite and > 0.
    pub fn table(s: &[f64], area: &[f64], ix: &[f64], iy: &[f64], j: &[f64]) -> Result<Self> {
        let n = s.len();
        if n < 2 {
            return Err(Error::invalid("s", format!("{n} rows"), ">= 2 rows"));
        }
        for (name, col) in [("area", area), ("ix", ix), ("iy", iy), ("j", j)] {
            if col.len() != n {
                return Err(Error::invalid(
                    format!("{name}.len()"),
                    col.len(),
                    format!("equal to the length of `s`, {n}"),
                ));
            }
        }
        let mut props = Vec::with_capacity(n);
        for i in 0..n {
            if !s[i].is_finite() || (i > 0 && s[i] <= s[i - 1]) {
                return Err(Error::invalid(
                    format!("s[{i}]"),
                    s[i],
                    "finite and strictly increasing (m)",
                ));
            }
            check_positive(&format!("area[{i}]"), area[i], "m^2")?;
            check_positive(&format!("ix[{i}]"), ix[i], "m^4")?;
            check_positive(&format!("iy[{i}]"), iy[i], "m^4")?;
            check_positive(&format!("j[{i}]"), j[i], "m^4")?;
            props.push(SectionProperties {
                area: area[i],
                ix: ix[i],
                iy: iy[i],
                j: j[i],
                radius: (area[i] / PI).sqrt(),
                radius_rate: 0.0,
            });
        }
        Ok(Self {
            kind: Kind::Table {
                s: s.to_vec(),
                props,
            },
        })
    }

    /// Section given by a user function of `s` (m). The function is checked at rod
    /// construction on a grid of points and must return finite, positive properties everywhere.
    pub fn function(f: SectionFn) -> Self {
        Self {
            kind: Kind::Function(f),
        }
    }

    /// Properties at arc length `s` (m) of a rod of length `length` (m).
    #[inline]
    pub fn properties(&self, s: f64, length: f64) -> SectionProperties {
        match &self.kind {
            Kind::Circular { radius } => SectionProperties::circle(*radius, 0.0),
            Kind::Tapered {
                base_radius,
                tip_radius,
            } => {
                let rate = (tip_radius - base_radius) / length;
                SectionProperties::circle(base_radius + rate * s, rate)
            }
            Kind::Tube {
                outer_radius,
                inner_radius,
            } => SectionProperties::tube(*outer_radius, *inner_radius),
            Kind::Table { s: ts, props } => table_lookup(ts, props, s),
            Kind::Function(f) => f(s),
        }
    }

    /// Whether the section is a user function of `s`.
    pub fn is_function(&self) -> bool {
        matches!(self.kind, Kind::Function(_))
    }

    /// Whether the properties are the same at every `s` (circles and tubes).
    pub fn is_uniform(&self) -> bool {
        matches!(self.kind, Kind::Circular { .. } | Kind::Tube { .. })
    }

    /// Inner-to-outer radius ratio `m` (0 for solid sections), used by the default shear
    /// coefficient.
    pub fn hollowness(&self) -> f64 {
        match &self.kind {
            Kind::Tube {
                outer_radius,
                inner_radius,
            } => inner_radius / outer_radius,
            _ => 0.0,
        }
    }

    /// Cowper's shear coefficient `k` (shear area `k A`) for Poisson's ratio `nu`:
    /// `6 (1 + nu) (1 + m²)² / ((7 + 6 nu)(1 + m²)² + (20 + 12 nu) m²)` with `m` the
    /// inner-to-outer radius ratio (`m = 0`: solid circle, `6 (1 + nu) / (7 + 6 nu)`, 0.886 at
    /// `nu = 0.3`). Tables and functions use the solid-circle value.
    ///
    /// # References
    /// G. R. Cowper, "The shear coefficient in Timoshenko's beam theory", J. Appl. Mech. 33(2),
    /// 1966, table 1.
    pub fn cowper_shear_coefficient(&self, nu: f64) -> f64 {
        let m2 = self.hollowness().powi(2);
        let a = (1.0 + m2).powi(2);
        6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m2)
    }

    /// Checks the section on `[0, length]`: tables must cover it, functions must return valid
    /// properties on a grid of `checks` + 1 points.
    pub(crate) fn check_on(&self, length: f64, checks: usize) -> Result<()> {
        match &self.kind {
            Kind::Table { s, .. } => {
                let (first, last) = (s[0], s[s.len() - 1]);
                if first > 0.0 || last < length {
                    return Err(Error::invalid(
                        "section.s",
                        format!("[{first}, {last}]"),
                        format!("a table covering [0, length] = [0, {length}] m"),
                    ));
                }
                Ok(())
            }
            Kind::Function(_) => {
                for i in 0..=checks {
                    let s = length * i as f64 / checks as f64;
                    self.properties(s, length)
                        .validated(&format!("section({s})"))?;
                }
                Ok(())
            }
            _ => {
                // Tapered sections are positive at both ends, hence everywhere.
                Ok(())
            }
        }
    }
}

fn table_lookup(ts: &[f64], props: &[SectionProperties], s: f64) -> SectionProperties {
    let n = ts.len();
    if s <= ts[0] {
        return props[0];
    }
    if s >= ts[n - 1] {
        return props[n - 1];
    }
    let i = ts.partition_point(|&t| t <= s).clamp(1, n - 1) - 1;
    let h = ts[i + 1] - ts[i];
    let x = (s - ts[i]) / h;
    let (a, b) = (&props[i], &props[i + 1]);
    let lerp = |p: f64, q: f64| p + (q - p) * x;
    let area = lerp(a.area, b.area);
    let radius = (area / PI).sqrt();
    SectionProperties {
        area,
        ix: lerp(a.ix, b.ix),
        iy: lerp(a.iy, b.iy),
        j: lerp(a.j, b.j),
        radius,
        radius_rate: (b.area - a.area) / h / (2.0 * PI * radius),
    }
}
