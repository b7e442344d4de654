# The layer rule of docs/ARCHITECTURE.md, checked: a header of include/bvhkit, or a source of src/,
# may include headers of its own folder and of lower layers only; and the library (include/ and src/)
# holds no benchmark workload. Run as `cmake -DROOT=<repo> -P tests/layering.cmake`; it fails naming
# every include or file that breaks the rule.
#
# Layers, lowest first. Two folders of one layer may not include each other (bvh and bsp, dynamic and
# query); the only allowed crossings are listed in `allowed` below.
#   0 error.hpp version.hpp tuning.hpp simd
#   1 math exec
#   2 primitives
#   3 volumes walk
#   4 bvh bsp convex
#   5 build
#   6 dynamic query
#   7 triangle_bvh.hpp
#   8 io mesh scene
#   9 bvhkit.hpp
cmake_policy(VERSION 3.25)  # a script has no project(): IN_LIST and the like need the policies set
set(rank_error.hpp 0)
set(rank_version.hpp 0)
set(rank_tuning.hpp 0)
set(rank_math 1)
set(rank_exec 1)
set(rank_simd 0)
set(rank_primitives 2)
set(rank_volumes 3)
set(rank_walk 3)
set(rank_bvh 4)
set(rank_bsp 4)
set(rank_convex 4)
set(rank_build 5)
set(rank_dynamic 6)
set(rank_query 6)
set(rank_triangle_bvh.hpp 7)
set(rank_io 8)
set(rank_mesh 8)
set(rank_scene 8)
set(rank_bvhkit.hpp 9)
# Includes across one layer that are allowed (the file or folder, then the folder it may include):
# mesh loading reads mesh files through io (src/mesh/load_mesh.cpp), and a scene's file
# (scene/scene_file.hpp) is written with io's envelope and holds a DynamicTree file. An entry that no
# include uses is itself an error, so the list cannot outlive the need for it.
set(allowed "mesh:io;scene:io")

set(broken "")
set(used_exceptions "")

# Every line that includes something, however it is spaced: `#include`, `# include`, indented.
set(include_line "^[ \t]*#[ \t]*include[ \t]*[<\"]")
set(include_path "^[ \t]*#[ \t]*include[ \t]*[<\"]([^>\"]+)[>\"].*")

# One file of the library: `file` (from ROOT) is in layer folder or file `part`. `library_header`:
# whether it is a public header, which must name every header of its own as "bvhkit/..." (a source
# may also include the private headers beside it).
macro(check_layers file part library_header)
    file(STRINGS "${ROOT}/${file}" lines REGEX "${include_line}")
    foreach(line ${lines})
        string(REGEX REPLACE "${include_path}" "\\1" target "${line}")
        if(${library_header} AND line MATCHES "^[ \t]*#[ \t]*include[ \t]*\"" AND
           NOT target MATCHES "^bvhkit/")
            # A relative include would slip past the check below.
            list(APPEND broken "${file} includes \"${target}\": not of the form \"bvhkit/...\"")
            continue()
        endif()
        if(NOT target MATCHES "^bvhkit/")
            continue()  # a standard, third-party or private header
        endif()
        string(REGEX REPLACE "^bvhkit/" "" target "${target}")
        if(NOT EXISTS "${ROOT}/include/bvhkit/${target}")
            list(APPEND broken "${file} includes bvhkit/${target}, which does not exist")
            continue()
        endif()
        string(REGEX MATCH "^[^/]+" target_part "${target}")
        if(target_part STREQUAL part)
            continue()
        endif()
        if(NOT DEFINED rank_${target_part})
            list(APPEND broken "${file} includes ${target}: no layer for '${target_part}'")
            continue()
        endif()
        set(ok FALSE)
        if(rank_${target_part} LESS rank_${part})
            set(ok TRUE)
        endif()
        foreach(exception ${allowed})
            if(exception STREQUAL "${file}:${target_part}" OR exception STREQUAL "${part}:${target_part}")
                set(ok TRUE)
                list(APPEND used_exceptions "${exception}")
            endif()
        endforeach()
        if(NOT ok)
            list(APPEND broken "${file} (layer ${rank_${part}}) includes ${target} (layer ${rank_${target_part}})")
        endif()
    endforeach()
endmacro()

file(GLOB_RECURSE headers RELATIVE "${ROOT}/include/bvhkit" "${ROOT}/include/bvhkit/*")
foreach(header ${headers})
    string(REGEX MATCH "^[^/]+" part "${header}")
    if(NOT DEFINED rank_${part})
        list(APPEND broken "include/bvhkit/${header}: '${part}' has no layer in tests/layering.cmake")
        continue()
    endif()
    check_layers("include/bvhkit/${header}" "${part}" TRUE)
endforeach()
# The sources follow the same rule: src/<folder>/ is the folder's layer; a source directly in src/
# names its part here.
set(source_part_build_options.cpp build)
file(GLOB_RECURSE sources RELATIVE "${ROOT}/src" "${ROOT}/src/*")
foreach(source ${sources})
    if(source MATCHES "/")
        string(REGEX MATCH "^[^/]+" part "${source}")
    elseif(DEFINED source_part_${source})
        set(part "${source_part_${source}}")
    else()
        list(APPEND broken "src/${source}: no part named for it in tests/layering.cmake")
        continue()
    endif()
    if(NOT DEFINED rank_${part})
        list(APPEND broken "src/${source}: '${part}' has no layer in tests/layering.cmake")
        continue()
    endif()
    check_layers("src/${source}" "${part}" FALSE)
endforeach()
foreach(exception ${allowed})
    if(NOT exception IN_LIST used_exceptions)
        list(APPEND broken "allowed exception '${exception}' is not used: remove it")
    endif()
endforeach()

# Benchmark workloads and their inputs (ray sets, poses) live in bench/, not in the library: no file
# of include/ or src/ may be one by name, nor include a header of bench/ (bench/CMakeLists.txt puts
# its folders on the include path, so a bare "ray_sets.hpp" would otherwise compile).
file(GLOB_RECURSE library_files RELATIVE "${ROOT}" "${ROOT}/include/*" "${ROOT}/src/*")
file(GLOB_RECURSE bench_headers RELATIVE "${ROOT}" "${ROOT}/bench/*.hpp" "${ROOT}/bench/*.h")
set(bench_names "")
foreach(bench_header ${bench_headers})
    get_filename_component(name "${bench_header}" NAME)
    list(APPEND bench_names "${name}")
endforeach()
foreach(file ${library_files})
    get_filename_component(name "${file}" NAME)
    if(name MATCHES "ray_sets|poses|workload|_bench")
        list(APPEND broken "${file}: named as a benchmark workload or input, which belongs in bench/")
    endif()
    file(STRINGS "${ROOT}/${file}" lines REGEX "${include_line}")
    foreach(line ${lines})
        string(REGEX REPLACE "${include_path}" "\\1" target "${line}")
        get_filename_component(target_name "${target}" NAME)
        # By name only for includes outside "bvhkit/": a library header may share a bench name.
        if(target MATCHES "(^|/)bench/" OR
           (NOT target MATCHES "^bvhkit/" AND target_name IN_LIST bench_names))
            list(APPEND broken "${file} includes \"${target}\", a header of bench/")
        endif()
    endforeach()
endforeach()

list(LENGTH headers count)
if(broken)
    list(JOIN broken "\n  " text)
    message(FATAL_ERROR "layering: the layer rule (docs/ARCHITECTURE.md) is broken:\n  ${text}")
endif()
message(STATUS "layering: ${count} headers follow the layer rule; include/ and src/ hold no workload")
