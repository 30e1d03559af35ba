// libFuzzer harness over the case loader (scripts/fuzz.sh builds it with clang, ASan and UBSan and
// runs it from the repository root on the seed corpus in tests/fuzz/corpus).
//
// The loader's contract, checked on every input: it returns a built case or throws CaseError whose
// message is one line naming the source ("fuzz.json: ..."). Anything else — another exception, a
// message without the source, a crash, a sanitizer report, a hang (libFuzzer's -timeout), an
// allocation of -malloc_limit_mb or more or a process beyond -rss_limit_mb (scripts/fuzz.sh says
// why the two differ) — is a finding. The pre-flight limits are lowered so that a valid case
// stays small: 256 MB for an MPM grid and its particles, 20 000 cells for a gmsh mesh.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "silentmpm/case.hpp"

namespace {
constexpr const char* kSource = "fuzz.json";

[[noreturn]] void finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_case: %s: %s\n", what, detail.c_str());
  std::abort();
}
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  smpm::LoadLimits limits;
  limits.memory_bytes = 256e6;
  limits.mesh_cells = 2e4;
  smpm::set_load_limits(limits);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const smpm::Case c = smpm::load_case_text(text, kSource);
    if (!c.solver && !c.fem) finding("a case without a region", "");
  } catch (const smpm::CaseError& e) {
    const std::string m = e.what();
    if (m.rfind(std::string(kSource) + ": ", 0) != 0)
      finding("a case error that does not name the source", m);
    if (m.find('\n') != std::string::npos) finding("a case error of more than one line", m);
    if (m.size() > 2100) finding("a case error over 2 000 characters", m.substr(0, 200));
  } catch (const std::exception& e) {
    finding("an exception other than CaseError", e.what());
  } catch (...) {
    finding("a non-standard exception", "");
  }
  return 0;
}
