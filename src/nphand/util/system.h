// Facts about the machine, for benchmark reports.
#pragma once

#include <string>

namespace nphand {

// The processor's model name and the number of online cores, e.g. "Intel Xeon ... (2 cores)".
std::string MachineDescription();

}  // namespace nphand
