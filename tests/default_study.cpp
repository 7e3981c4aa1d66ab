#include "default_study.hpp"

namespace stepbench::test_support {

const study& default_study() {
  static const study s = run_sweep(sweep_options{});
  return s;
}

}  // namespace stepbench::test_support
