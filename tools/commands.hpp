#pragma once
// One function per subcommand of the bvhkit command; argv[0] is the subcommand's name. They return
// the process exit code (0 ok, 1 error, 2 bad usage) and may throw bvhkit::Error, which main()
// reports.
namespace bvhkit::tools {

int version_command(int argc, char** argv);
int info_command(int argc, char** argv);
int render_command(int argc, char** argv);
int trace_command(int argc, char** argv);
int draw_tree_command(int argc, char** argv);  // tools/draw_tree.cpp
int closest_command(int argc, char** argv);    // tools/closest.cpp
int collide_command(int argc, char** argv);    // tools/collide.cpp
int distance_command(int argc, char** argv);   // tools/distance.cpp
int bsp_command(int argc, char** argv);        // tools/bsp.cpp

}  // namespace bvhkit::tools
