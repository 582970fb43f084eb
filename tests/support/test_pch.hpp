// Precompiled once for the tests that link the problems and the harness (the
// default links of tests/CMakeLists.txt: cstab_test_pch, reused by each):
// GoogleTest and the headers of methods/pairs_pch.hpp.
#pragma once

#include <gtest/gtest.h>

#include "methods/pairs_pch.hpp"
