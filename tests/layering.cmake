# The layer rule of docs/ARCHITECTURE.md, checked: a header of include/bvhkit may include headers of
# its own folder and of lower layers only. Run as `cmake -DROOT=<repo> -P tests/layering.cmake`;
# it fails naming every include that breaks the rule.
#
# Layers, lowest first (a folder may include its own layer's folders only where listed as allowed):
#   0 error.hpp version.hpp
#   1 math exec
#   2 primitives
#   3 volumes
#   4 bvh bsp
#   5 build dynamic
#   6 query
#   7 triangle_bvh.hpp
#   8 io mesh
#   9 bvhkit.hpp
set(rank_error.hpp 0)
set(rank_version.hpp 0)
set(rank_math 1)
set(rank_exec 1)
set(rank_primitives 2)
set(rank_volumes 3)
set(rank_bvh 4)
set(rank_bsp 4)
set(rank_build 5)
set(rank_dynamic 5)
set(rank_query 6)
set(rank_triangle_bvh.hpp 7)
set(rank_io 8)
set(rank_mesh 8)
set(rank_bvhkit.hpp 9)
# Includes across one layer that are allowed: the file, then the folder or file it may include.
# The insertion builder and its optimizer reuse the dynamic tree's insertion and rotations.
set(allowed
    "build/insertion.hpp:dynamic"
    "build/reinsertion.hpp:dynamic"
    "mesh:io")

file(GLOB_RECURSE headers RELATIVE "${ROOT}/include/bvhkit" "${ROOT}/include/bvhkit/*.hpp")
set(broken "")
foreach(header ${headers})
    string(REGEX MATCH "^[^/]+" part "${header}")
    if(NOT DEFINED rank_${part})
        list(APPEND broken "${header}: folder '${part}' has no layer in tests/layering.cmake")
        continue()
    endif()
    file(STRINGS "${ROOT}/include/bvhkit/${header}" lines REGEX "^#include \"bvhkit/")
    foreach(line ${lines})
        string(REGEX REPLACE "^#include \"bvhkit/([^\"]+)\".*" "\\1" target "${line}")
        string(REGEX MATCH "^[^/]+" target_part "${target}")
        if(target_part STREQUAL part)
            continue()
        endif()
        if(NOT DEFINED rank_${target_part})
            list(APPEND broken "${header} includes ${target}: no layer for '${target_part}'")
            continue()
        endif()
        set(ok FALSE)
        if(rank_${target_part} LESS rank_${part})
            set(ok TRUE)
        endif()
        foreach(exception ${allowed})
            if(exception STREQUAL "${header}:${target_part}" OR exception STREQUAL "${part}:${target_part}")
                set(ok TRUE)
            endif()
        endforeach()
        if(NOT ok)
            list(APPEND broken "${header} (layer ${rank_${part}}) includes ${target} (layer ${rank_${target_part}})")
        endif()
    endforeach()
endforeach()
list(LENGTH headers count)
if(broken)
    list(JOIN broken "\n  " text)
    message(FATAL_ERROR "layering: a lower layer includes a higher one (or its own layer's other folder):\n  ${text}")
endif()
message(STATUS "layering: ${count} headers follow the layer rule")
