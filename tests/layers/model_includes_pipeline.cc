// Compiled against the model layer alone: a header of a layer above it (here
// the pipeline's) is not on its include path, so this must fail to build.
#include "skybake/model/atmosphere.h"
#include "skybake/pipeline/pipeline.h"

int LayerProbeWrongWay() { return int(sizeof(skybake::BakeOptions)); }
