#define DOCTEST_CONFIG_IMPLEMENT
#include "tests/skip.hpp"

MW_TEST_MAIN
