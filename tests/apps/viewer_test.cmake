# Included by tests/apps/CMakeLists.txt: the viewer's test. Its arithmetic
# (viewer_controls.cpp) is compiled in; the windowed cases run the emoface
# binary on an Xvfb server the test starts itself (viewer_x11.cpp, Xlib).
find_package(X11 REQUIRED)
emoface_add_test(apps_viewer_test
  SOURCES viewer_test.cpp viewer_x11.cpp ${PROJECT_SOURCE_DIR}/apps/src/viewer_controls.cpp
  DEPS emoface::render emoface::render_io X11::X11
  LABELS noleak)
target_include_directories(apps_viewer_test PRIVATE ${PROJECT_SOURCE_DIR}/apps/src)
target_compile_definitions(apps_viewer_test PRIVATE EMOFACE_BINARY="$<TARGET_FILE:emoface>")
add_dependencies(apps_viewer_test emoface)
