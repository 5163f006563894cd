"""Binding surface of the material laws, the fit and the silicone library; the tensile-CSV reader,
the ``softrod materials`` / ``softrod fit`` commands and ``plot_fit``. The physics (closed forms,
tangents, fit accuracy) is tested in Rust (crates/softrod/tests/hyperelastic.rs)."""

import json
import subprocess
import sys

import numpy as np
import pytest

import softrod
from softrod import (
    SILICONES,
    Hookean,
    Linearised,
    MooneyRivlin,
    NeoHookean,
    Ogden,
    ParameterError,
    UniaxialLaw,
    Yeoh,
    fit_uniaxial,
    read_tensile_csv,
    silicone,
)
from softrod.cli import main
from softrod.plot import plot_fit

DATA = softrod.examples.DATA / "silicone-tensile"
DRAGON_SKIN_10 = DATA / "Dragon Skin 10 MEDIUM.csv"

LAWS = [
    Hookean(3e5),
    Linearised(1.2e5, 1.0),
    NeoHookean(1e5),
    MooneyRivlin(6e4, 1e4),
    Yeoh(2e4, 3e3, -100.0),
    Ogden([1e4, 2e3], [2.0, -2.0]),
]
IDS = [law.model_name for law in LAWS]
# Methods taking a stretch (> 0) and one taking an engineering strain (> -1).
BY_STRETCH = ["nominal_stress", "true_stress", "nominal_tangent"]
BY_STRAIN = ["tangent_modulus"]


# ----------------------------------------------------------------------------- laws


@pytest.mark.parametrize("law", LAWS, ids=IDS)
def test_laws_share_the_base_class_and_report_their_parameters(law):
    assert isinstance(law, UniaxialLaw)
    assert law.model_name in repr(law)
    params = law.parameters
    assert isinstance(params, dict) and params
    for name, value in params.items():
        assert getattr(law, name) == value
    assert law.small_strain_modulus > 0


@pytest.mark.parametrize("law", LAWS, ids=IDS)
@pytest.mark.parametrize("method", BY_STRETCH + BY_STRAIN + ["stretch_from_nominal_stress"])
def test_evaluation_is_vectorised_over_any_shape(law, method):
    fn = getattr(law, method)
    # Values valid for every method: stretches and strains > 0, stresses inside every law's
    # range.
    x = np.array([[0.2, 0.5, 1.5], [2.0, 0.8, 1.1]])
    out = fn(x)
    assert isinstance(out, np.ndarray) and out.shape == (2, 3) and out.dtype == np.float64
    for idx in np.ndindex(x.shape):
        assert out[idx] == fn(float(x[idx]))  # element by element, bit for bit
    assert fn(x.T).shape == (3, 2)  # non-contiguous views are read in logical order
    np.testing.assert_array_equal(fn(x.T), out.T)
    assert fn([0.5, 1.5]).shape == (2,)  # sequences
    assert fn(np.empty((0,))).shape == (0,)
    # A number (Python or NumPy, or a 0-d array) gives a float.
    for scalar in (0.5, np.float64(0.5), np.array(0.5)):
        y = fn(scalar)
        assert type(y) is float and y == fn(np.array([0.5]))[0]
    assert type(fn(2)) is float  # integers are converted


@pytest.mark.parametrize("law", LAWS, ids=IDS)
def test_stress_measures_and_inverse_agree_through_the_binding(law):
    stretch = np.linspace(0.5, 2.5, 9)
    np.testing.assert_allclose(law.true_stress(stretch), stretch * law.nominal_stress(stretch))
    np.testing.assert_allclose(
        law.stretch_from_nominal_stress(law.nominal_stress(stretch)), stretch, rtol=1e-12
    )
    assert law.tangent_modulus(0.0) == pytest.approx(law.small_strain_modulus, rel=1e-12)


@pytest.mark.parametrize("method", BY_STRETCH)
def test_bad_stretch_raises_naming_it_and_its_index(method):
    fn = getattr(Yeoh(2e4), method)
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ParameterError) as info:
            fn(bad)
        assert info.value.parameter == "stretch"
    with pytest.raises(ParameterError) as info:
        fn([1.0, 2.0, -0.5])
    assert info.value.parameter == "stretch[2]"
    assert "stretch[2]" in str(info.value)
    with pytest.raises(ParameterError) as info:
        fn([[1.0, 2.0], [3.0, 0.0]])
    assert info.value.parameter == "stretch[1, 1]"


@pytest.mark.parametrize(
    ("method", "bad", "name"),
    [
        ("tangent_modulus", -1.0, "strain"),
        ("tangent_modulus", float("nan"), "strain"),
        ("stretch_from_nominal_stress", float("inf"), "nominal_stress"),
    ],
)
def test_other_bad_arguments_name_their_parameter(method, bad, name):
    fn = getattr(NeoHookean(1e5), method)
    with pytest.raises(ParameterError) as info:
        fn(bad)
    assert info.value.parameter == name
    with pytest.raises(ParameterError) as info:
        fn([0.5, bad])
    assert info.value.parameter == f"{name}[1]"


def test_unreachable_stress_is_a_parameter_error():
    # The linear law would need stretch <= 0 for P <= -E.
    with pytest.raises(ParameterError) as info:
        Hookean(1e5).stretch_from_nominal_stress(-2e5)
    assert info.value.parameter == "nominal_stress"


@pytest.mark.parametrize(
    ("make", "name"),
    [
        (lambda: Hookean(0.0), "youngs_modulus"),
        (lambda: Linearised(-1.0, 1.0), "secant_modulus"),
        (lambda: Linearised(1e5, 0.0), "reference_strain"),
        (lambda: Linearised.from_secant_point(-1e5, 1.0), "nominal_stress"),
        (lambda: NeoHookean(float("nan")), "mu"),
        (lambda: MooneyRivlin(1e4, -2e4), "c10 + c01"),
        (lambda: Yeoh(-1.0), "c10"),
        (lambda: Yeoh(1e4, float("inf")), "c20"),
        (lambda: Ogden([1e4], [2.0, 3.0]), "mu"),
        (lambda: Ogden([1e4, 1e3], [2.0, 0.0]), "alpha[1]"),
    ],
)
def test_bad_constructor_arguments_name_the_parameter(make, name):
    with pytest.raises(ParameterError) as info:
        make()
    assert info.value.parameter == name


def test_constructors_and_defaults():
    assert Yeoh(1e4).parameters == {"c10": 1e4, "c20": 0.0, "c30": 0.0}
    line = Linearised.from_secant_point(6.9e4, 1.0)
    assert isinstance(line, Linearised)
    assert (line.secant_modulus, line.reference_strain) == (6.9e4, 1.0)
    og = Ogden(np.array([1e4, 2e3]), (2, -2))
    assert og.mu == [1e4, 2e3] and og.alpha == [2.0, -2.0]
    with pytest.raises(TypeError):
        UniaxialLaw()


def test_check_stable_raises_on_an_unstable_range():
    law = silicone("Dragon Skin 10").yeoh  # c30 < 0: loses stability a little above 3.7
    assert law.check_stable(0.5, 3.0) is None
    with pytest.raises(ParameterError) as info:
        law.check_stable(1.0, 5.0)
    assert "Yeoh" in info.value.parameter
    with pytest.raises(ParameterError) as info:
        law.check_stable(2.0, 1.0)
    assert info.value.parameter == "stretch_max"


# ----------------------------------------------------------------------------- fitting


def test_fit_round_trip_on_synthetic_data():
    truth = Yeoh(2e4, 1.5e3, -40.0)
    strain = np.linspace(0.02, 2.0, 60)
    stress = truth.nominal_stress(1 + strain)
    fit = fit_uniaxial(strain, stress, "yeoh")
    assert isinstance(fit.model, Yeoh)
    assert fit.parameters == fit.model.parameters
    for name, value in truth.parameters.items():
        assert fit.parameters[name] == pytest.approx(value, rel=1e-8)
    assert fit.points == 60 and fit.iterations == 0 and fit.stress_measure == "nominal"
    assert fit.rms < 1e-6 and fit.max_abs_residual < 1e-5 and fit.r_squared > 1 - 1e-12
    assert fit.stretch_range == (pytest.approx(1.02), pytest.approx(3.0))
    assert "UniaxialFit(Yeoh(" in repr(fit)


@pytest.mark.parametrize(
    ("strain_measure", "to_strain"),
    [
        ("engineering", lambda lam: lam - 1),
        ("stretch", lambda lam: lam),
        ("logarithmic", np.log),
    ],
)
@pytest.mark.parametrize("stress_measure", ["nominal", "true"])
def test_fit_accepts_every_measure(strain_measure, to_strain, stress_measure):
    truth = NeoHookean(5e4)
    lam = np.linspace(1.05, 2.5, 30)
    stress = truth.true_stress(lam) if stress_measure == "true" else truth.nominal_stress(lam)
    fit = fit_uniaxial(
        to_strain(lam),
        stress,
        "neo-hookean",
        strain_measure=strain_measure,
        stress_measure=stress_measure,
    )
    assert isinstance(fit.model, NeoHookean)
    assert fit.model.mu == pytest.approx(5e4, rel=1e-10)
    assert fit.stress_measure == stress_measure


def test_fit_models_options_and_range():
    lam = np.linspace(1.02, 3.0, 50)
    stress = Ogden([1.5e4, 1e2], [2.5, 6.0]).nominal_stress(lam)
    kinds = {
        "neo-hookean": NeoHookean,
        "Mooney_Rivlin": MooneyRivlin,
        "yeoh": Yeoh,
        "ogden": Ogden,
        "linearised": Linearised,
    }
    for model, cls in kinds.items():
        assert isinstance(fit_uniaxial(lam - 1, stress, model).model, cls)
    one = fit_uniaxial(lam - 1, stress, "yeoh", terms=1)
    assert one.parameters["c20"] == 0.0 and one.parameters["c30"] == 0.0
    ogden3 = fit_uniaxial(lam - 1, stress, "ogden", terms=3, nonnegative=True)
    assert len(ogden3.model.mu) == 3 and min(ogden3.model.mu) >= 0.0
    part = fit_uniaxial(lam - 1, stress, "yeoh", stretch_range=(1.0, 2.0))
    assert part.points == int(np.sum(lam <= 2.0)) and part.stretch_range[1] <= 2.0


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        (dict(model="gent"), "model"),
        (dict(model="neo-hookean", terms=2), "terms"),
        (dict(model="yeoh", terms=4), "terms"),
        (dict(model="yeoh", terms=0), "terms"),
        (dict(model="ogden", terms=9), "terms"),
        (dict(strain_measure="percent"), "strain_measure"),
        (dict(stress_measure="cauchy"), "stress_measure"),
        (dict(stretch_range=(5.0, 6.0)), "stretch_max"),
        (dict(stretch_range=(0.0, 2.0)), "stretch_min"),
        (dict(model="ogden", max_iterations=0), "max_iterations"),
        (dict(model="ogden", tolerance=-1.0), "tolerance"),
    ],
)
def test_bad_fit_arguments_name_the_parameter(kwargs, name):
    strain = np.linspace(0.1, 1.0, 10)
    with pytest.raises(ParameterError) as info:
        fit_uniaxial(strain, 1e4 * strain, **kwargs)
    assert info.value.parameter == name


def test_bad_fit_data_names_the_point():
    with pytest.raises(ParameterError) as info:
        fit_uniaxial([0.1, -1.5, 0.3], [1.0, 2.0, 3.0])
    assert info.value.parameter == "strain[1]"
    with pytest.raises(ParameterError) as info:
        fit_uniaxial([0.1, 0.2], [1.0, float("nan")])
    assert info.value.parameter == "stress[1]"
    with pytest.raises(ParameterError) as info:
        fit_uniaxial([0.1, 0.2], [1.0])
    assert info.value.parameter == "stress"


# ----------------------------------------------------------------------------- library


def test_silicone_library():
    assert isinstance(SILICONES, tuple) and len(SILICONES) >= 5
    assert "Elastosil M4601" not in SILICONES  # unverified source: removed
    for name in SILICONES:
        s = silicone(name)
        assert s.name == name and name in repr(s)
        assert isinstance(s.neo_hookean, NeoHookean)
        assert isinstance(s.yeoh, Yeoh)
        assert s.mooney_rivlin is None or isinstance(s.mooney_rivlin, MooneyRivlin)
        assert "Marechal" in s.source and "10.1089/soro.2019.0115" in s.source
        lo, hi = s.fit_stretch_range
        s.yeoh.check_stable(lo, hi)
    assert silicone("dragonskin_10").name == "Dragon Skin 10"
    with pytest.raises(ParameterError) as info:
        silicone("Sylgard 184")
    assert info.value.parameter == "name"


def test_library_is_the_fit_of_the_vendored_curve():
    curve = read_tensile_csv(DRAGON_SKIN_10)
    lib = silicone("Dragon Skin 10")
    fit = curve.fit("yeoh", stretch_range=lib.fit_stretch_range)
    for name, value in lib.yeoh.parameters.items():
        assert fit.parameters[name] == pytest.approx(value, rel=1e-5)


def test_public_names_are_exported():
    for name in (
        "UniaxialLaw",
        "UniaxialFit",
        "Silicone",
        "fit_uniaxial",
        "silicone",
        "SILICONES",
        "read_tensile_csv",
        "TensileCurve",
    ):
        assert name in softrod.__all__ and hasattr(softrod, name)


# ----------------------------------------------------------------------------- CSV reader


@pytest.mark.parametrize("path", sorted(DATA.glob("*.csv")), ids=lambda p: p.stem)
def test_reader_on_every_vendored_file(path):
    curve = read_tensile_csv(path)
    assert curve.strain_measure == "engineering" and curve.stress_measure == "nominal"
    assert curve.name == path.stem and curve.metadata["Standard"] == "ASTM D412"
    assert curve.strain.shape == curve.stress.shape and len(curve) > 300
    # MPa -> Pa: peak stresses of these silicones are 0.1-10 MPa.
    assert 1e5 < curve.stress.max() < 1e7
    true = read_tensile_csv(path, columns="true")
    assert true.strain_measure == "logarithmic" and true.stress_measure == "true"
    # The file's "true strain" is ln(stretch), and its true stress is stretch * nominal (to
    # the file's rounding).
    np.testing.assert_allclose(true.stretch, curve.stretch, rtol=2e-3, atol=2e-3)
    big = curve.stress > 1e4
    np.testing.assert_allclose(true.stress[big], (curve.stretch * curve.stress)[big], rtol=2e-2)


def test_reader_first_rows_of_a_vendored_file():
    curve = read_tensile_csv(DRAGON_SKIN_10)
    # First data row: 0.2;0.0436133333333333;0.0020766343;0.0445783731527225;0.00198801196097173
    assert curve.strain[0] == 0.0445783731527225
    assert curve.stress[0] == pytest.approx(1988.01196097173, rel=1e-15)
    assert curve.metadata["Material"] == "DragonSkin10"


def test_reader_plain_csv_with_options(tmp_path):
    law = NeoHookean(4e4)
    lam = np.linspace(1.1, 2.0, 10)
    p = tmp_path / "plain.csv"
    rows = "\n".join(
        f"{(x - 1) * 100:.12g}, {y / 1e3:.12g}"
        for x, y in zip(lam, law.nominal_stress(lam), strict=True)
    )
    p.write_text("# my test\nstrain (%), stress (kPa)\n" + rows + "\n")
    curve = read_tensile_csv(p, strain_unit="percent", stress_unit="kPa")
    np.testing.assert_allclose(curve.stretch, lam, rtol=1e-12)
    fit = curve.fit("neo-hookean")
    assert fit.model.mu == pytest.approx(4e4, rel=1e-9)
    # Stretch and true stress, whitespace separated, no header.
    q = tmp_path / "plain.txt"
    q.write_text(
        "\n".join(f"{x:.15g}\t{y:.15g}" for x, y in zip(lam, law.true_stress(lam), strict=True))
    )
    curve = read_tensile_csv(q, strain_measure="stretch", stress_measure="true")
    assert curve.fit("neo-hookean").model.mu == pytest.approx(4e4, rel=1e-12)


@pytest.mark.parametrize(
    ("content", "kwargs", "name"),
    [
        ("0.1, 1\n0.2, x\n", {}, "bad.csv:2"),
        ("0.1, 1, 3\n", {}, "bad.csv:1"),
        ("strain, stress\n", {}, "path"),
        ("0.1, 1\n", dict(stress_unit="psi"), "stress_unit"),
        ("0.1, 1\n", dict(strain_unit="permille"), "strain_unit"),
        ("0.1, 1\n", dict(strain_measure="green"), "strain_measure"),
        ("0.1, 1\n", dict(stress_measure="cauchy"), "stress_measure"),
        ("1.1, 1\n", dict(strain_measure="stretch", strain_unit="percent"), "strain_unit"),
    ],
)
def test_reader_bad_input_names_it(tmp_path, content, kwargs, name):
    p = tmp_path / "bad.csv"
    p.write_text(content)
    with pytest.raises(ParameterError) as info:
        read_tensile_csv(p, **kwargs)
    assert info.value.parameter == name


def test_reader_bad_database_columns(tmp_path):
    with pytest.raises(ParameterError) as info:
        read_tensile_csv(DRAGON_SKIN_10, columns="green")
    assert info.value.parameter == "columns"
    p = tmp_path / "db.csv"
    p.write_text("Time (s);True Strain;True Stress (MPa)\n0.1;0.1;0.1\n")
    with pytest.raises(ParameterError) as info:
        read_tensile_csv(p)
    assert info.value.parameter == "path"


# ----------------------------------------------------------------------------- CLI and plot


def test_cli_materials_lists_the_library(capsys):
    assert main(["materials"]) == 0
    out = capsys.readouterr().out
    for name in SILICONES:
        assert name in out
    assert "Marechal" in out and "Yeoh c10" in out
    assert main(["materials", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [d["name"] for d in data] == list(SILICONES)
    assert data[0]["yeoh"] == silicone(SILICONES[0]).yeoh.parameters


def test_cli_fit_prints_parameters_and_errors_and_plots(tmp_path, capsys):
    png = tmp_path / "fit.png"
    argv = ["fit", str(DRAGON_SKIN_10), "--model", "yeoh", "--terms", "3", "--stretch-max", "3"]
    assert main([*argv, "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    lib = silicone("Dragon Skin 10").yeoh
    assert f"c10 = {lib.c10:.6g} Pa" in out and f"c30 = {lib.c30:.6g} Pa" in out
    assert "RMS" in out and "R^2" in out and "fitted points: 87" in out
    assert png.read_bytes()[:4] == b"\x89PNG" and png.stat().st_size > 10_000
    models = ["-m", "neo-hookean", "mooney-rivlin", "ogden", "--stretch-max", "3"]
    assert main(["fit", str(DRAGON_SKIN_10), *models]) == 0
    out = capsys.readouterr().out
    assert "NeoHookean:" in out and "MooneyRivlin:" in out and "Ogden:" in out


@pytest.mark.parametrize(
    ("argv", "name"),
    [
        (["fit", "no-such-file.csv"], "FILE"),
        (["fit", str(DRAGON_SKIN_10), "--model", "gent"], "model"),
        (["fit", str(DRAGON_SKIN_10), "--terms", "7"], "terms"),
        (["fit", str(DRAGON_SKIN_10), "-m", "neo-hookean", "--terms", "2"], "terms"),
        (["fit", str(DRAGON_SKIN_10), "--stretch-max", "0.5"], "stretch_max"),
        (["fit", str(DRAGON_SKIN_10), "--columns", "green"], "columns"),
    ],
)
def test_cli_fit_bad_input_exits_2_with_one_line(argv, name, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("softrod: error:") and f"`{name}`" in err[0]


# Three valid points whose least-squares Yeoh fit has c10 < 0 (a fuzz run's file).
FLAT_START = "strain,stress\n0,0\n0.1,0.0\n0.2,0.01\n"


def test_a_non_physical_fitted_coefficient_is_named_as_a_result(tmp_path):
    path = tmp_path / "curve.csv"
    path.write_text(FLAT_START)
    curve = read_tensile_csv(path)
    with pytest.raises(ParameterError) as exc:
        curve.fit("yeoh")
    text = str(exc.value)
    assert "invalid parameter `c10`" not in text and exc.value.parameter == "data"
    assert "yeoh law" in text and "fitted coefficient c10 = -0.00175" in text
    assert "3 points" in text and "more data" in text and "another law" in text
    with pytest.raises(ParameterError, match=r"fitted coefficient c10 \+ c01 = -0\.0118"):
        curve.fit("mooney-rivlin")
    # A law the data can be fitted with is unchanged.
    fit = curve.fit("neo-hookean")
    direct = fit_uniaxial(curve.strain, curve.stress, "neo-hookean")
    assert fit.parameters == direct.parameters
    # Errors about the caller's own arguments still name them.
    with pytest.raises(ParameterError) as exc:
        curve.fit("ogden")
    assert exc.value.parameter == "data" and "at least 4 points" in str(exc.value)
    with pytest.raises(ParameterError) as exc:
        curve.fit("yeoh", terms=7)
    assert exc.value.parameter == "terms"


def test_cli_fit_names_a_non_physical_fitted_coefficient(tmp_path, capsys):
    path = tmp_path / "curve.csv"
    path.write_text(FLAT_START)
    assert main(["fit", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("softrod: error:")
    assert "`c10`" not in err[0] and "fitted coefficient c10 = -0.00175" in err[0]
    assert "yeoh law" in err[0] and str(path) in err[0] and "another law" in err[0]
    # With several models the failing one is reported and the others are fitted.
    assert main(["fit", str(path), "-m", "yeoh", "neo-hookean"]) == 0
    out = capsys.readouterr().out
    assert "yeoh: fit failed:" in out and "fitted coefficient c10" in out
    assert "NeoHookean: mu = " in out


def test_cli_fit_bad_file_has_no_traceback(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("0.1, 1\n0.2, oops\n")
    r = subprocess.run(
        [sys.executable, "-m", "softrod", "fit", str(p)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert r.returncode == 2
    assert "Traceback" not in r.stderr and "bad.csv:2" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_plot_fit_draws_data_fits_and_residuals():
    curve = read_tensile_csv(DRAGON_SKIN_10)
    fits = [curve.fit(m, stretch_range=(0.5, 3.0)) for m in ("neo-hookean", "yeoh")]
    fig = plot_fit(curve, fits)
    ax, ax_r = fig.axes
    labels = [ln.get_label() for ln in ax.get_lines()]
    assert labels[0] == curve.name and "not fitted" in labels
    assert any(lb.startswith("NeoHookean (RMS") for lb in labels)
    assert any(lb.startswith("Yeoh (RMS") for lb in labels)
    # One residual line per fit, at the fitted points, in kPa.
    res = [ln for ln in ax_r.get_lines() if len(ln.get_xdata()) == fits[1].points]
    assert len(res) == 2
    expected = (fits[1].model.nominal_stress(curve.stretch) - curve.stress) / 1e3
    used = (curve.stretch >= 0.5) & (curve.stretch <= 3.0)
    np.testing.assert_allclose(res[1].get_ydata(), expected[used])
    # A single fit and custom labels work too.
    fig = plot_fit(curve, fits[1], labels=["mine"], title="t")
    assert "mine" in [ln.get_label() for ln in fig.axes[0].get_lines()]


def test_study_command_runs_both_materials_and_writes_figures(tmp_path, capsys):

    from softrod.cli import main
    from softrod.study import compliance_study

    robot = softrod.examples.path("pneumatic_arm")
    res = compliance_study(robot, levels=2, max_pressure=30e3, out_dir=tmp_path, log=None)
    assert set(res) == {"hyperelastic", "linear"}
    for r in res.values():
        assert r.pressures.shape == (8, 3) and np.all(np.isfinite(r.max_compliance))
        assert r.gamma_c_tip.shape == (5, 3) and r.centre_periphery_ratio > 0
    assert len(list(tmp_path.glob("pneumatic_*.png"))) == 4
    assert (
        main(
            [
                "study",
                str(robot),
                "--levels",
                "2",
                "--max-pressure",
                "2e4",
                "--out",
                str(tmp_path / "cli"),
            ]
        )
        == 0
    )
    assert "centre -> periphery" in capsys.readouterr().out
    assert main(["study", str(robot), "--max-pressure", "-1"]) == 2


def test_the_core_fit_names_the_data_not_a_fitted_coefficient():
    # fit_uniaxial itself (not only TensileCurve.fit and the CLI) named a fitted `c10` as if
    # it were an input; the refusal is now the data's, made where the law is built.
    strain, stress = np.array([0.0, 0.1, 0.2]), np.array([0.0, 1e-4, 5e-3])
    with pytest.raises(ParameterError) as exc:
        fit_uniaxial(strain, stress, "yeoh")
    assert exc.value.parameter == "data"
    assert "yeoh law" in str(exc.value) and "fitted coefficient c10 = -" in str(exc.value)


def test_a_curve_beyond_any_modulus_or_without_strain_is_named(tmp_path):
    # (1e308 Pa overflowed the fit, "initial slope inf kPa"; all-zero strains gave nan.)
    with pytest.raises(softrod.ParameterError, match=r"`stress\[1\]` = 1e\+308"):
        softrod.TensileCurve(np.array([0.0, 0.1, 0.2]), np.array([0.0, 1e308, 3.0]))
    flat = softrod.TensileCurve(np.zeros(4), np.zeros(4))
    with pytest.raises(softrod.ParameterError, match="smallest values all 0"):
        flat.initial_slope()
    header_only = tmp_path / "empty.csv"
    lines = (
        softrod.examples.DATA.joinpath("silicone-tensile", "Dragon Skin 10 MEDIUM.csv")
        .read_text(encoding="utf-8-sig")
        .splitlines()
    )
    from softrod.analysis.materials import _DATABASE_HEADER

    k = next(i for i, ln in enumerate(lines) if ln.startswith(_DATABASE_HEADER))
    header_only.write_text("\n".join(lines[: k + 1]) + "\n")
    with pytest.raises(softrod.ParameterError, match=r"empty\.csv.*at least one row"):
        softrod.read_tensile_csv(header_only)
