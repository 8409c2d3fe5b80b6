// Compiled against the output layer (and so every layer below it): the
// pipeline's headers are still not found. The manifest once included
// pipeline.h; this keeps the file formats from depending on the bake again.
#include "skybake/output/manifest.h"
#include "skybake/pipeline/pipeline.h"

int LayerProbeOutputWrongWay() { return int(sizeof(skybake::BakeOptions)); }
