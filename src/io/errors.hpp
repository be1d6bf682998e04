// Moved to math/errors.hpp (the bottom layer). Kept for src/physics/, whose includes change with the element
// builder's rework (issue 11, item 2); remove once nothing includes it.
#pragma once

#include "math/errors.hpp"
