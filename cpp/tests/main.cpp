// Catch2's main for the core's unit tests (ctest runs them: docs/architecture.md, "Development").
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
