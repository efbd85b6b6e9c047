#include "bake/bake.h"
