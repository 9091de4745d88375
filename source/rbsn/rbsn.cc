// The rbsn method: RBSN::Model is the registered Run::SteppingMethod.
#include "rbsn/model.h"

HYSTERON_REGISTER_METHOD(hysteron::RBSN::Model,
                         "rbsn",
                         "the Rigid-Body-Spring Network: Voronoi cells as rigid bodies joined by "
                         "Bouc-Wen springs at their facets, static, quasi-static and dynamic, with "
                         "brittle fracture; 2D and 3D; see doc/rbsn.md");
