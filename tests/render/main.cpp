// The main of test_render (the preview's and the plots' tests); the cases live in the other files.
#define DOCTEST_CONFIG_IMPLEMENT
#include "tests/skip.hpp"

MW_TEST_MAIN
