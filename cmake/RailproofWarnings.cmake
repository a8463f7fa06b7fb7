# Common warning and sanitizer flags, applied per target through railproof_options.
add_library(railproof_options INTERFACE)
target_compile_options(railproof_options INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion)
if(RAILPROOF_WERROR)
  target_compile_options(railproof_options INTERFACE -Werror)
endif()
if(RAILPROOF_SANITIZE)
  target_compile_options(railproof_options INTERFACE -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  target_link_options(railproof_options INTERFACE -fsanitize=address,undefined)
endif()
# Runtime (safety) modules additionally forbid exceptions and RTTI.
add_library(railproof_runtime_options INTERFACE)
target_link_libraries(railproof_runtime_options INTERFACE railproof_options)
target_compile_options(railproof_runtime_options INTERFACE -fno-exceptions -fno-rtti)
