/// @file BuildModel.cpp
/// `pneuma-build-model ANATOMY OUT`: the default model at build time when the app (and so pneuma-cli) is not
/// built, as in the sanitizer build (CONTRIBUTING.md). The same three calls as `pneuma-cli model build
/// --no-preview`, so the model is the same; a bad input is one line on stderr and exit 2.

#include <exception>
#include <iostream>

#include "pneuma/meshing/AnatomyParams.h"
#include "pneuma/meshing/ModelBuilder.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: pneuma-build-model ANATOMY.json OUT_DIR\n";
    return 2;
  }
  try {
    pneuma::meshing::writeModelDirectory(pneuma::meshing::buildModel(pneuma::meshing::loadAnatomy(argv[1])),
                                         argv[2]);
  } catch (const std::exception& e) {
    std::cerr << "pneuma-build-model: error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
