#pragma once
// Helpers shared by the film tests (tests/physics/test_film_study.cpp and
// tests/errors/test_film_case.cpp): the case files of studies/film.
#include <filesystem>
#include <string>

#ifndef SMPM_SOURCE_DIR
#define SMPM_SOURCE_DIR "."
#endif

namespace smpm::film_testing {

inline std::filesystem::path case_path(const std::string& name) {
  return std::filesystem::path(SMPM_SOURCE_DIR) / "studies/film/cases" / (name + ".json");
}

}  // namespace smpm::film_testing
