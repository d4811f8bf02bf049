# Debian ships two Bullet builds side by side; their config files only set variables with
# paths relative to BULLET_ROOT_DIR, so wrap the chosen one in an imported target.
# Input: CONFORM_DOUBLE. Output: target conform_bullet_deps (INTERFACE IMPORTED).
if(TARGET conform_bullet_deps)
  return()
endif()
if(CONFORM_DOUBLE)
  find_package(Bullet REQUIRED CONFIG CONFIGS BulletConfig-float64.cmake)
else()
  find_package(Bullet REQUIRED CONFIG CONFIGS BulletConfig.cmake)
endif()

set(_conform_bullet_root "${BULLET_ROOT_DIR}")
# Only the libraries of libbullet-dev are linked (BulletInverseDynamics lives in
# libbullet-extras-dev and is not needed).
set(_conform_bullet_libs)
set(_conform_suffix "")
if(CONFORM_DOUBLE)
  set(_conform_suffix "-float64")
endif()
foreach(_lib BulletSoftBody BulletDynamics BulletCollision LinearMath)
  set(_lib "${_lib}${_conform_suffix}")
  find_library(_conform_lib_${_lib} NAMES ${_lib}
               HINTS "${_conform_bullet_root}/${BULLET_LIBRARY_DIRS}" NO_DEFAULT_PATH)
  if(NOT _conform_lib_${_lib})
    message(FATAL_ERROR "Conform: Bullet library ${_lib} not found under "
                        "${_conform_bullet_root}/${BULLET_LIBRARY_DIRS}")
  endif()
  list(APPEND _conform_bullet_libs ${_conform_lib_${_lib}})
endforeach()

add_library(conform_bullet_deps INTERFACE IMPORTED)
set_target_properties(conform_bullet_deps PROPERTIES
  INTERFACE_INCLUDE_DIRECTORIES "${_conform_bullet_root}/${BULLET_INCLUDE_DIR}"
  INTERFACE_LINK_LIBRARIES "${_conform_bullet_libs}")
if(CONFORM_DOUBLE)
  set_property(TARGET conform_bullet_deps PROPERTY
               INTERFACE_COMPILE_DEFINITIONS BT_USE_DOUBLE_PRECISION)
endif()
