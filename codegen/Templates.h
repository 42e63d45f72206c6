// The fixed parts of generated code (the files in templates/ and the plugin
// ABI header), embedded into psc at build time.
#pragma once

#include <string>

namespace psc::codegen::templates {

const std::string& core();          // templates/core.h
const std::string& movement();      // templates/movement.h
const std::string& engine();        // templates/engine.h
const std::string& ruleTable();     // templates/rule_table.h
const std::string& stateKey();      // templates/state_key.h
const std::string& gameModule();    // templates/game_module.h
const std::string& cudaKernels();   // templates/cuda_kernels.h
const std::string& pluginHeader();  // runtime/psc_plugin.h
const std::string& gameModuleHeader();  // runtime/plugin_host/GameModule.h

}  // namespace psc::codegen::templates
