//! A library of named silicones with sourced parameters (Neo-Hookean, Mooney–Rivlin, Yeoh),
//! fitted to measured uniaxial curves.

use std::fmt;

use super::hyperelastic::{MooneyRivlin, NeoHookean, Yeoh};
use crate::error::{Error, Result};

/// Named silicones with sourced hyperelastic parameters.
///
/// Every parameter set is a least-squares fit by
/// [`crate::model::material::fit::fit_uniaxial`] (nominal stress, unweighted, exact linear solve) to the measured
/// tensile curve of the Soft Robotics Materials Database, restricted to stretch `λ <= 3`
/// (engineering strain <= 200 %, see [`Silicone::fit_stretch_range`]):
///
/// > L. Marechal, P. Balland, L. Lindenroth, F. Petrou, C. Kontovounisios, F. Bello, "Toward a
/// > Common Framework and Database of Materials for Soft Robotics", Soft Robotics 8(3), 2021,
/// > doi:10.1089/soro.2019.0115; data github.com/LucMarechal/Soft-Robotics-Materials-Database,
/// > folder `Tensile-Tests-Data/`, commit 8ff66c3bdc17bd226eabe83b778e13ea1e2ef8ce, licensed
/// > ODbL 1.0 (database) / DbCL 1.0 (contents).
///
/// Those curves are ASTM D412 tests (3 × 6 mm section, 33 mm gauge, 450 mm/min) with strain
/// taken from the crosshead, which overstates strain: the moduli are therefore on the low side,
/// and batch, cure and test method change them by more than the choice of model (datasheets
/// differ by 2–4× for the Ecoflex grades). The fits are reproduced, with their errors, by
/// `cargo run --release -p softrod --example fit_silicones` (reading the vendored
/// `data/silicone-tensile/`); the constants are stored to six significant digits.
///
/// These curves stiffen with strain, so unconstrained Mooney–Rivlin fits come out with
/// `C01 < 0` and are stable only in tension or mild compression (stretch bounds in each
/// entry); three-term Yeoh fits have `C30 < 0` and lose stability a little above `λ = 3.7`
/// (Dragon Skin) or 4.4 (Ecoflex). Check [`UniaxialLaw::check_stable`](super::hyperelastic::UniaxialLaw::check_stable) on the stretch range of
/// the application; prefer Yeoh where a section is compressed (bending).
///
/// The measured curves are vendored in `data/silicone-tensile/` (with their licence). Literature
/// parameter sets whose primary source could not be checked are deliberately not included.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Silicone {
    /// Smooth-On Ecoflex 00-30.
    ///
    /// Fit errors on the 86 points with λ ≤ 3 (RMS / max |residual| of the nominal stress):
    /// Neo-Hookean 1.343 / 2.712 kPa (R² 0.9908); Mooney–Rivlin 0.419 / 1.096 kPa (R²
    /// 0.9991), stable for λ ≥ 0.503 only; Yeoh 0.412 / 1.468 kPa (R² 0.9991), stable for λ
    /// ≤ 4.71.
    Ecoflex0030,
    /// Smooth-On Ecoflex 00-50.
    ///
    /// Fit errors on the 87 points with λ ≤ 3: Neo-Hookean 3.157 / 6.458 kPa (R² 0.9788);
    /// Mooney–Rivlin 0.846 / 2.983 kPa (R² 0.9985), stable for λ ≥ 0.687 only; Yeoh 0.524 /
    /// 3.610 kPa (R² 0.9994), stable for λ ≤ 4.38.
    Ecoflex0050,
    /// Smooth-On Dragon Skin 10 (MEDIUM).
    ///
    /// Fit (file `Dragon Skin 10 MEDIUM.csv`) errors on the 87 points with λ ≤ 3:
    /// Neo-Hookean 24.59 / 45.63 kPa (R² 0.904); Mooney–Rivlin 6.031 / 9.770 kPa (R² 0.9942),
    /// stable for λ ≥ 0.997 only (tension only; its initial modulus 6 (c10 + c01) is near
    /// zero); Yeoh 0.842 / 3.553 kPa (R² 0.99989), stable for 0.110 ≤ λ ≤ 3.77.
    DragonSkin10,
    /// Smooth-On Dragon Skin 20.
    ///
    /// Fit errors on the 87 points with λ ≤ 3: Neo-Hookean 57.28 / 111.1 kPa (R² 0.923);
    /// Mooney–Rivlin 10.93 / 23.80 kPa (R² 0.9972), stable for λ ≥ 0.958 only; Yeoh 4.297 /
    /// 8.583 kPa (R² 0.99957), stable for 0.113 ≤ λ ≤ 3.71.
    DragonSkin20,
    /// Smooth-On Dragon Skin 30.
    ///
    /// Fit errors on the 87 points with λ ≤ 3: Neo-Hookean 69.30 / 131.6 kPa (R² 0.936);
    /// Mooney–Rivlin 14.17 / 26.26 kPa (R² 0.9973), stable for λ ≥ 0.922 only; Yeoh 3.107 /
    /// 6.360 kPa (R² 0.99987), stable for 0.112 ≤ λ ≤ 3.71.
    DragonSkin30,
}

/// Sourced parameters of one silicone (Pa).
struct SiliconeParams {
    name: &'static str,
    mu: f64,
    mooney_rivlin: Option<(f64, f64)>,
    yeoh: (f64, f64, f64),
    stretch_max: f64,
    source: &'static str,
}

impl Silicone {
    /// Every silicone of the library.
    pub const ALL: [Silicone; 5] = [
        Silicone::Ecoflex0030,
        Silicone::Ecoflex0050,
        Silicone::DragonSkin10,
        Silicone::DragonSkin20,
        Silicone::DragonSkin30,
    ];

    fn params(self) -> SiliconeParams {
        match self {
            Silicone::Ecoflex0030 => SiliconeParams {
                name: "Ecoflex 00-30",
                mu: 17204.9,
                mooney_rivlin: Some((10148.3, -3614.42)),
                yeoh: (7733.53, 139.149, -4.06163),
                stretch_max: 3.0,
                source: MARECHAL_2021,
            },
            Silicone::Ecoflex0050 => SiliconeParams {
                name: "Ecoflex 00-50",
                mu: 25112.6,
                mooney_rivlin: Some((16260.3, -8659.60)),
                yeoh: (10411.7, 346.974, -10.5176),
                stretch_max: 3.0,
                source: MARECHAL_2021,
            },
            Silicone::DragonSkin10 => SiliconeParams {
                name: "Dragon Skin 10",
                mu: 78634.9,
                mooney_rivlin: Some((68341.6, -67855.7)),
                yeoh: (21589.8, 3044.25, -111.600),
                stretch_max: 3.0,
                source: MARECHAL_2021,
            },
            Silicone::DragonSkin20 => SiliconeParams {
                name: "Dragon Skin 20",
                mu: 211548.0,
                mooney_rivlin: Some((174249.0, -160087.0)),
                yeoh: (63798.8, 7372.43, -287.254),
                stretch_max: 3.0,
                source: MARECHAL_2021,
            },
            Silicone::DragonSkin30 => SiliconeParams {
                name: "Dragon Skin 30",
                mu: 286574.0,
                mooney_rivlin: Some((225892.0, -193122.0)),
                yeoh: (92174.8, 9028.40, -356.941),
                stretch_max: 3.0,
                source: MARECHAL_2021,
            },
        }
    }

    /// Display name, e.g. `"Dragon Skin 10"`.
    pub fn name(self) -> &'static str {
        self.params().name
    }

    /// Looks a silicone up by name, ignoring case, spaces, `-` and `_` (`"ecoflex 00-30"`,
    /// `"DragonSkin10"`, `"dragon_skin_20"`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`name`) listing the known names otherwise.
    pub fn from_name(name: &str) -> Result<Self> {
        let key = |s: &str| {
            s.chars()
                .filter(|c| c.is_ascii_alphanumeric())
                .map(|c| c.to_ascii_lowercase())
                .collect::<String>()
        };
        let wanted = key(name);
        Self::ALL
            .into_iter()
            .find(|s| key(s.name()) == wanted)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|s| s.name()).collect();
                Error::invalid("name", name, format!("one of {}", names.join(", ")))
            })
    }

    /// Neo-Hookean law (see [`Silicone::source`]).
    pub fn neo_hookean(self) -> NeoHookean {
        NeoHookean {
            mu: self.params().mu,
        }
    }

    /// Two-parameter Mooney–Rivlin law, where a sourced one exists (every current entry has
    /// one; `None` is kept for literature entries without a measured curve).
    pub fn mooney_rivlin(self) -> Option<MooneyRivlin> {
        self.params()
            .mooney_rivlin
            .map(|(c10, c01)| MooneyRivlin { c10, c01 })
    }

    /// Yeoh law (three terms for the fitted silicones).
    pub fn yeoh(self) -> Yeoh {
        let (c10, c20, c30) = self.params().yeoh;
        Yeoh { c10, c20, c30 }
    }

    /// Stretch range `(min, max)` of the data the parameters were fitted to; the laws are only
    /// validated there. `None` where a source does not state it (no current entry).
    pub fn fit_stretch_range(self) -> Option<(f64, f64)> {
        let p = self.params();
        p.stretch_max.is_finite().then_some((1.0, p.stretch_max))
    }

    /// Where the parameters come from (for citations).
    pub fn source(self) -> &'static str {
        self.params().source
    }
}

impl fmt::Display for Silicone {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Source note of the fitted entries.
const MARECHAL_2021: &str =
    "least-squares fit (softrod fit_uniaxial, nominal stress, stretch 1 to 3) \
to the tensile curve of the Soft Robotics Materials Database: L. Marechal et al., Soft Robotics \
8(3), 2021, doi:10.1089/soro.2019.0115, github.com/LucMarechal/Soft-Robotics-Materials-Database \
commit 8ff66c3b, Tensile-Tests-Data (ODbL 1.0 / DbCL 1.0)";
