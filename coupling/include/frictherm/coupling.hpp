#pragma once
// Umbrella header of frictherm::coupling, the front door of the library: scenes, the run loop, the
// thermal coupling, ensembles, output and reading results back.
//
//   #include <frictherm/coupling.hpp>
//   namespace fc = frictherm::coupling;
//   fc::RunOptions opt;
//   opt.output = "out.h5";
//   opt.observer = [](const fc::StepView& s) { /* per-step diagnostics */ };
//   fc::RunResult r = fc::run_scene(fc::load_scene("examples/sliding_block_heating.json"), opt);
//   fc::SeriesTable series = fc::read_series(r.output);
//
// It includes the mechanics and thermal umbrella headers too.
#include <frictherm/mechanics.hpp>
#include <frictherm/thermal.hpp>

#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/coupler.hpp>
#include <frictherm/coupling/csv_export.hpp>
#include <frictherm/coupling/ensemble.hpp>
#include <frictherm/coupling/h5_output.hpp>
#include <frictherm/coupling/heat_handoff.hpp>
#include <frictherm/coupling/heat_sources.hpp>
#include <frictherm/coupling/hotspot_fates.hpp>
#include <frictherm/coupling/hotspots.hpp>
#include <frictherm/coupling/json_reader.hpp>
#include <frictherm/coupling/microstructure.hpp>
#include <frictherm/coupling/results.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>
#include <frictherm/coupling/scene_contact.hpp>
#include <frictherm/coupling/scene_thermal.hpp>
#include <frictherm/coupling/scene_value_observer.hpp>
#include <frictherm/coupling/thermal_assembly.hpp>
#include <frictherm/coupling/thread_policy.hpp>
#include <frictherm/coupling/xdmf.hpp>
