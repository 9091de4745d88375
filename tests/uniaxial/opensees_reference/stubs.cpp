// Stand-ins for the parts of OpenSees' interpreter that the material files reference but
// the driver never calls: the command-line parsers of the OPS_BoucWen... factory functions.
// The error stream is OpenSees' own StandardStream. Part of hysteron, not of OpenSees.
#include <OPS_Globals.h>
#include <StandardStream.h>
#include <elementAPI.h>

#include <cstdio>
#include <cstdlib>

StandardStream sserr;
OPS_Stream    *opserrPtr = &sserr;

namespace
{
  [[noreturn]] void
  not_available(const char *name)
  {
    std::fprintf(stderr, "%s: OpenSees' interpreter is not part of the reference driver\n", name);
    std::abort();
  }
} // namespace

extern "C" int
OPS_GetNumRemainingInputArgs()
{
  not_available("OPS_GetNumRemainingInputArgs");
}

extern "C" int
OPS_GetIntInput(int *, int *)
{
  not_available("OPS_GetIntInput");
}

extern "C" int
OPS_GetDoubleInput(int *, double *)
{
  not_available("OPS_GetDoubleInput");
}
