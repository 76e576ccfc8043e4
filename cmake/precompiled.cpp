// The translation unit that builds the shared precompiled header (src/pspslam/CMakeLists.txt).
