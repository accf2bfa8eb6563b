# Sources of the light-transport building blocks, added to toyrt_core:
#   target_sources(toyrt_core PRIVATE camera/camera.cpp ...)
