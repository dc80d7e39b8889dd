// Loads SDFormat files with libsdformat (the parser Gazebo uses), warnings and unknown
// elements treated as errors. Prints one line per model: name, links, joints, frames and the
// total mass (kg); exits 1 on any error. Built by tests/test_sdf.py.
#include <iomanip>
#include <iostream>
#include <sdf/sdf.hh>

int main(int argc, char **argv) {
  int status = 0;
  for (int i = 1; i < argc; ++i) {
    sdf::ParserConfig config;
    config.SetWarningsPolicy(sdf::EnforcementPolicy::ERR);
    config.SetUnrecognizedElementsPolicy(sdf::EnforcementPolicy::ERR);
    sdf::Root root;
    const sdf::Errors errors = root.Load(argv[i], config);
    for (const auto &error : errors) {
      std::cout << "error " << argv[i] << ": " << error.Message() << "\n";
      status = 1;
    }
    const sdf::Model *model = root.Model();
    if (!errors.empty() || model == nullptr) {
      status = 1;
      continue;
    }
    double mass = 0.0;
    for (uint64_t k = 0; k < model->LinkCount(); ++k) {
      mass += model->LinkByIndex(k)->Inertial().MassMatrix().Mass();
    }
    std::cout << std::setprecision(12) << "model " << model->Name() << " links " << model->LinkCount() << " joints "
              << model->JointCount() << " frames " << model->FrameCount() << " mass " << mass
              << "\n";
  }
  return status;
}
