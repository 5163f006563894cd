//! `softrod._core`: the PyO3 binding of the softrod core.
//!
//! This crate only converts arrays, maps the core's one error type to Python exceptions (in
//! `errors::to_py_err`) and releases the GIL around solves. All numerics live in the `softrod`
//! crate. It is split like the core: `model` (the robot description), `statics`,
//! `compliance`, `pcc`, `planar`, `materials`, `batch` (sweeps); argument conversions in `convert`, errors in
//! `errors`.

use pyo3::prelude::*;

mod batch;
mod callbacks;
mod compliance;
mod contact;
mod convert;
mod errors;
mod inverse;
mod materials;
mod model;
mod pcc;
mod planar;
mod sections;
mod statics;

/// The compiled core of softrod.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "ParameterError",
        m.py().get_type::<errors::ParameterError>(),
    )?;
    m.add(
        "ConvergenceError",
        m.py().get_type::<errors::ConvergenceError>(),
    )?;
    m.add(
        "TargetUnreachableError",
        m.py().get_type::<errors::TargetUnreachableError>(),
    )?;
    m.add("ParameterTypeError", errors::parameter_type_error(m.py())?)?;
    m.add("InternalError", m.py().get_type::<errors::InternalError>())?;
    m.add("MAX_SAMPLES", softrod::limits::MAX_SAMPLES)?;
    m.add("MAX_ITERATIONS", softrod::limits::MAX_ITERATIONS)?;
    m.add("MAX_LOAD_NUMBER", softrod::limits::MAX_LOAD_NUMBER)?;
    m.add("MAX_LENGTH", softrod::limits::MAX_LENGTH)?;
    m.add("MAX_MODULUS", softrod::limits::MAX_MODULUS)?;
    m.add("MAX_BENDING_ANGLE", softrod::limits::MAX_BENDING_ANGLE)?;
    m.add("MAX_OFFSET_RATIO", softrod::limits::MAX_OFFSET_RATIO)?;
    m.add("MAX_STARTS", softrod::MAX_STARTS)?;
    m.add("MAX_FRICTION", softrod::limits::MAX_FRICTION)?;
    m.add("MAX_MODULUS", softrod::limits::MAX_MODULUS)?;
    m.add(
        "StabilityWarning",
        m.py().get_type::<errors::StabilityWarning>(),
    )?;
    m.add(
        "StabilityError",
        m.py().get_type::<errors::StabilityError>(),
    )?;
    m.add_class::<planar::PlanarCableArm>()?;
    m.add_class::<planar::PlanarSolution>()?;
    m.add_class::<planar::PlanarBatch>()?;
    m.add_function(wrap_pyfunction!(planar::backbone_distance, m)?)?;
    m.add_class::<sections::PySection>()?;
    m.add_class::<sections::CircularSection>()?;
    m.add_class::<sections::TaperedCircularSection>()?;
    m.add_class::<sections::TubeSection>()?;
    m.add_class::<sections::TableSection>()?;
    m.add_class::<sections::FunctionSection>()?;
    m.add_class::<sections::LinearElastic>()?;
    m.add_class::<model::Rod>()?;
    m.add_class::<model::Tendon>()?;
    m.add_class::<model::Chamber>()?;
    m.add_class::<model::PointLoad>()?;
    m.add_class::<model::Loads>()?;
    m.add_class::<statics::StaticsSolution>()?;
    m.add_function(wrap_pyfunction!(statics::solve_statics, m)?)?;
    m.add_class::<statics::robot::RobotModel>()?;
    m.add_function(wrap_pyfunction!(statics::robot::_solve_robot, m)?)?;
    m.add_function(wrap_pyfunction!(statics::actuation_jacobian, m)?)?;
    m.add_class::<inverse::InverseWarmState>()?;
    m.add_function(wrap_pyfunction!(inverse::_inverse_statics, m)?)?;
    m.add_function(wrap_pyfunction!(inverse::_pcc_inverse_statics, m)?)?;
    m.add_function(wrap_pyfunction!(model::_rebuild, m)?)?;
    m.add_class::<materials::PyUniaxialLaw>()?;
    m.add_class::<materials::Hookean>()?;
    m.add_class::<materials::Linearised>()?;
    m.add_class::<materials::NeoHookean>()?;
    m.add_class::<materials::MooneyRivlin>()?;
    m.add_class::<materials::Yeoh>()?;
    m.add_class::<materials::Ogden>()?;
    m.add_class::<materials::UniaxialFit>()?;
    m.add_class::<materials::Silicone>()?;
    m.add_function(wrap_pyfunction!(materials::fit_uniaxial, m)?)?;
    m.add_function(wrap_pyfunction!(materials::_uniaxial_fit, m)?)?;
    m.add_function(wrap_pyfunction!(materials::silicone, m)?)?;
    m.add("SILICONES", materials::silicone_names(m.py())?)?;
    m.add_function(wrap_pyfunction!(statics::_time_solve_statics, m)?)?;
    m.add_class::<compliance::Compliance>()?;
    m.add_class::<compliance::TangentCompliance>()?;
    m.add_class::<compliance::Eigenscrews>()?;
    m.add_function(wrap_pyfunction!(compliance::compliance, m)?)?;
    m.add_function(wrap_pyfunction!(compliance::tangent_compliance, m)?)?;
    m.add_function(wrap_pyfunction!(compliance::eigenscrews, m)?)?;
    m.add_function(wrap_pyfunction!(compliance::_workspace_map, m)?)?;
    m.add_function(wrap_pyfunction!(batch::_sweep, m)?)?;
    m.add_class::<pcc::PccRobot>()?;
    m.add_class::<pcc::PccSolution>()?;
    m.add_function(wrap_pyfunction!(pcc::pcc_solve, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_arc_pose, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_arc_poses, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::_pcc_robot, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_arc_frames, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_arc_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_chain_pose, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_chain_frames, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_chain_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_arc_from_tip, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_arc_from_tip_with_length, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_tendon_displacements, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_tendon_displacement_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_arc_from_tendon_displacements, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_tendon_displacement_misfit, m)?)?;
    m.add_function(wrap_pyfunction!(
        pcc::pcc_arc_from_tendon_displacements_jacobian,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_arc_from_tendon_tensions, m)?)?;
    m.add_function(wrap_pyfunction!(
        pcc::pcc_arc_from_tendon_tensions_jacobian,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_arc_from_pressures, m)?)?;
    m.add_function(wrap_pyfunction!(pcc::pcc_arc_from_pressures_jacobian, m)?)?;
    Ok(())
}
