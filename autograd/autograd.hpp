// Everything of the autograd library in one include.
#pragma once

#include "autograd/tensor.hpp"
#include "autograd/ops_elementwise.hpp"
#include "autograd/ops_matmul.hpp"
#include "autograd/ops_reduce.hpp"
#include "autograd/ops_shape.hpp"
#include "autograd/ops_index.hpp"
#include "autograd/ops_vec3.hpp"
#include "autograd/ops_norm.hpp"
#include "autograd/ops_loss.hpp"
#include "autograd/ops_grouped.hpp"
#include "autograd/ops_complex.hpp"
#include "autograd/ops_wire.hpp"
#include "autograd/ops_conv.hpp"
#include "autograd/gradcheck.hpp"
