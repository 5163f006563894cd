//! Fits every material law to the measured tensile curves of the Soft Robotics Materials
//! Database (Marechal et al., Soft Robotics 8(3), 2021, doi:10.1089/soro.2019.0115; ODbL 1.0 /
//! DbCL 1.0) and prints the parameters and errors as Markdown tables.
//!
//! Usage: `cargo run --release -p softrod --example fit_silicones [-- <dir with the CSV files>]`;
//! the default directory is the copy vendored with the repository, `data/silicone-tensile/`.
//!
//! Each file has 17 `;`-separated header lines, then the column names
//! `Time (s);True Strain;True Stress (MPa);Engineering Strain;Engineering Stress (MPa)`.
//! "True strain" there is the logarithmic strain `ln λ`, not `λ − 1`. The fits use the
//! engineering columns (the measured ones: crosshead strain and force / initial area), converted
//! from MPa to Pa; the true columns are derived from them.
#![allow(clippy::too_many_lines)]

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use softrod::{
    fit_stats, fit_uniaxial, FitOptions, ModelKind, Silicone, StrainMeasure, StressMeasure,
    UniaxialData, UniaxialLaw, UniaxialModel,
};

/// The files fitted, and the library entry each one backs (if any).
const FILES: [(&str, Option<Silicone>); 6] = [
    ("Ecoflex 00-10.csv", None),
    ("Ecoflex 00-30.csv", Some(Silicone::Ecoflex0030)),
    ("Ecoflex 00-50.csv", Some(Silicone::Ecoflex0050)),
    ("Dragon Skin 10 MEDIUM.csv", Some(Silicone::DragonSkin10)),
    ("Dragon Skin 20.csv", Some(Silicone::DragonSkin20)),
    ("Dragon Skin 30.csv", Some(Silicone::DragonSkin30)),
];

/// Reads the engineering strain and engineering stress (converted to Pa) of one file.
fn read_curve(path: &Path) -> Result<(Vec<f64>, Vec<f64>), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    let header = lines
        .by_ref()
        .find(|l| l.starts_with("Time (s);"))
        .ok_or_else(|| format!("{}: no column header line", path.display()))?;
    let names: Vec<&str> = header.split(';').map(str::trim).collect();
    let col = |name: &str| {
        names
            .iter()
            .position(|n| *n == name)
            .ok_or_else(|| format!("{}: no column {name:?}", path.display()))
    };
    let (i_strain, i_stress) = (col("Engineering Strain")?, col("Engineering Stress (MPa)")?);
    let (mut strain, mut stress) = (Vec::new(), Vec::new());
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let fields: Vec<&str> = line.split(';').collect();
        let get = |i: usize| -> Result<f64, String> {
            fields
                .get(i)
                .and_then(|f| f.trim().parse::<f64>().ok())
                .ok_or_else(|| format!("{}: bad line {line:?}", path.display()))
        };
        strain.push(get(i_strain)?);
        stress.push(get(i_stress)? * 1e6);
    }
    Ok((strain, stress))
}

fn params(model: &UniaxialModel) -> String {
    match model {
        UniaxialModel::Linearised(l) => format!("E_l = {:.4} kPa", l.secant_modulus() / 1e3),
        UniaxialModel::NeoHookean(l) => format!("mu = {:.4} kPa", l.mu() / 1e3),
        UniaxialModel::MooneyRivlin(l) => {
            format!(
                "c10 = {:.4} kPa, c01 = {:.4} kPa",
                l.c10() / 1e3,
                l.c01() / 1e3
            )
        }
        UniaxialModel::Yeoh(l) => format!(
            "c10 = {:.4} kPa, c20 = {:.5} kPa, c30 = {:.4e} kPa",
            l.c10() / 1e3,
            l.c20() / 1e3,
            l.c30() / 1e3
        ),
        UniaxialModel::Ogden(l) => {
            let terms: Vec<String> = l
                .mu()
                .iter()
                .zip(l.alpha())
                .map(|(m, a)| format!("({:.4} kPa, {:.4})", m / 1e3, a))
                .collect();
            format!("(mu, alpha) = {}", terms.join(", "))
        }
        UniaxialModel::Hookean(l) => format!("E = {:.4} kPa", l.youngs_modulus() / 1e3),
    }
}

/// Stretch interval around 1 on which `dP/dλ > 0`: scanned on `[0.1, 50]` for the first sign
/// change on each side, its root then bisected (`<0.1` / `>50` when stable to the scan's end).
fn stable_range(law: &dyn UniaxialLaw) -> String {
    const STEPS: usize = 4000;
    let stable = |l: f64| law.nominal_slope_unchecked(l) > 0.0;
    let scan = |end: f64| {
        let mut last = 1.0;
        for i in 1..=STEPS {
            let l = end.powf(i as f64 / STEPS as f64);
            if !stable(l) {
                let (mut inside, mut outside) = (last, l);
                for _ in 0..60 {
                    let mid = 0.5 * (inside + outside);
                    if stable(mid) {
                        inside = mid;
                    } else {
                        outside = mid;
                    }
                }
                return format!("{inside:.4}");
            }
            last = l;
        }
        format!("{}{end}", if end < 1.0 { "<" } else { ">" })
    };
    format!("[{}, {}]", scan(0.1), scan(50.0))
}

fn main() -> ExitCode {
    let dir = std::env::args().nth(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/silicone-tensile"),
        PathBuf::from,
    );
    if !dir.is_dir() {
        eprintln!(
            "fit_silicones: no directory {} (usage: fit_silicones [<dir with the Soft Robotics \
             Materials Database CSV files>])",
            dir.display()
        );
        return ExitCode::from(2);
    }
    let kinds = [
        ("Linearised", ModelKind::Linearised, false),
        ("Neo-Hookean", ModelKind::NeoHookean, false),
        ("Mooney-Rivlin", ModelKind::MooneyRivlin, false),
        ("Mooney-Rivlin (c >= 0)", ModelKind::MooneyRivlin, true),
        ("Yeoh 3", ModelKind::Yeoh { terms: 3 }, false),
        ("Yeoh 3 (c >= 0)", ModelKind::Yeoh { terms: 3 }, true),
        ("Ogden 2", ModelKind::Ogden { terms: 2 }, false),
        ("Ogden 2 (mu >= 0)", ModelKind::Ogden { terms: 2 }, true),
    ];
    // Library range first (what the `Silicone` constants come from), then the whole curve.
    for (label, stretch_max) in [
        ("stretch 1 to 3 (engineering strain <= 200 %)", 3.0),
        ("whole curve, to break", f64::INFINITY),
    ] {
        println!("\n### Fits on {label}\n");
        println!("| material | points | model | parameters | RMS (kPa) | R² | max abs (kPa) | stable stretch range |");
        println!("|---|---|---|---|---|---|---|---|");
        for (file, _) in FILES {
            let (strain, stress) = match read_curve(&dir.join(file)) {
                Ok(c) => c,
                Err(e) => {
                    eprintln!("{e}");
                    return ExitCode::FAILURE;
                }
            };
            let data = UniaxialData::new(
                &strain,
                StrainMeasure::Engineering,
                &stress,
                StressMeasure::Nominal,
            )
            .and_then(|d| d.within(1e-3, stretch_max.min(1e6)));
            let data = match data {
                Ok(d) => d,
                Err(e) => {
                    eprintln!("{file}: {e}");
                    return ExitCode::FAILURE;
                }
            };
            let name = file.trim_end_matches(".csv");
            for (kind_label, kind, nonnegative) in kinds {
                let options = FitOptions {
                    nonnegative,
                    ..FitOptions::default()
                };
                match fit_uniaxial(&data, kind, &options) {
                    Ok(fit) => {
                        println!(
                            "| {name} | {} | {kind_label} | {} | {:.3} | {:.5} | {:.3} | {} |",
                            fit.stats.points,
                            params(&fit.model),
                            fit.stats.rms / 1e3,
                            fit.stats.r_squared,
                            fit.stats.max_abs_residual / 1e3,
                            stable_range(fit.model.as_law())
                        );
                    }
                    Err(e) => println!(
                        "| {name} | {} | {kind_label} | fit failed: {e} | | | | |",
                        data.len()
                    ),
                }
            }
        }
    }
    // The library constants, evaluated on the data they were fitted to.
    println!("\n### Library constants (`softrod::Silicone`) on stretch 1 to 3\n");
    println!(
        "| material | model | parameters | RMS (kPa) | R² | max abs (kPa) | stable stretch range |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (file, silicone) in FILES {
        let Some(silicone) = silicone else { continue };
        let Ok((strain, stress)) = read_curve(&dir.join(file)) else {
            return ExitCode::FAILURE;
        };
        let Ok(data) = UniaxialData::new(
            &strain,
            StrainMeasure::Engineering,
            &stress,
            StressMeasure::Nominal,
        )
        .and_then(|d| d.within(1e-3, 3.0)) else {
            return ExitCode::FAILURE;
        };
        let mut laws: Vec<UniaxialModel> =
            vec![silicone.neo_hookean().into(), silicone.yeoh().into()];
        laws.extend(silicone.mooney_rivlin().map(UniaxialModel::from));
        for law in laws {
            let s = fit_stats(law.as_law(), &data);
            println!(
                "| {} | {} | {} | {:.3} | {:.5} | {:.3} | {} |",
                silicone.name(),
                law.model_name(),
                params(&law),
                s.rms / 1e3,
                s.r_squared,
                s.max_abs_residual / 1e3,
                stable_range(law.as_law())
            );
        }
    }
    ExitCode::SUCCESS
}
