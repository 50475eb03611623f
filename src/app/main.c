#include "app/cli.h"

int main(int argc, char **argv)
{
    return ptr_cli_main(argc, argv);
}
