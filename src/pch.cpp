// The unit that precompiles mcrt/mcrt.hpp for the executable (src/CMakeLists.txt).
