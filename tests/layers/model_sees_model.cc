// Compiled against the model layer alone: its own headers are found (the
// control of layer_include_wrong_way_fails).
#include "skybake/model/atmosphere.h"
#include "skybake/gpu_shared.h"

int LayerProbeModel() { return int(sizeof(skybake::AtmosphereParams)); }
