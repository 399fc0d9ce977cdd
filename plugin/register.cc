// Registers recruit.sma when librecruit_sma.so is loaded (dlopen, mj_loadPluginLibrary,
// mujoco.PLUGINS_DIR, or a program linked against the library).
#include <mujoco/mujoco.h>

#include "plugin/sma_plugin.h"

mjPLUGIN_LIB_INIT(recruit_sma) { recruit::sma::RegisterSmaPlugin(); }
