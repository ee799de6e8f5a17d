#pragma once
/// \file
/// The suite's output: JSON for scenarios, methods and runs (README.md in this folder gives the
/// schema), and the flat CSV. Non-finite numbers are written as null.

#include "accuracy.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace impetus::accuracy {

nlohmann::json result_to_json(const RunResult& result);
RunResult result_from_json(const nlohmann::json& json);
nlohmann::json method_to_json(const Method& method);
/// A scenario's description (no runs): id, group, title, scene, overrides, kind, duration, steps,
/// measures, criterion, the errors' meanings and the primary error.
nlohmann::json scenario_to_json(const Scenario& scenario);

/// The CSV header and one row for a run.
std::string csv_header();
std::string csv_row(const Scenario& scenario, const Method& method, const RunResult& result);

}  // namespace impetus::accuracy
