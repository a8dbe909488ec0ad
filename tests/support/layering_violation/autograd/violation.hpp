// A planted layering violation: autograd may not include nn (tests/check_layering.cmake).
#pragma once
#include "nn/module.hpp"
