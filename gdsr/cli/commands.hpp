// Subcommands of the gdsr executable. Each command file defines one add_xxx_command that
// registers its subcommand (and its callback) on the top-level app; main.cpp calls them.
#pragma once

namespace CLI {
class App;
}

void add_data_command(CLI::App& app);   // train/cmd_data.cpp: gdsr data make|preview|import-md|check
void add_data_compare_command(CLI::App& data);  // train/cmd_data_compare.cpp: gdsr data compare (under `data`)
void add_data_table_command(CLI::App& data);    // train/cmd_data_table.cpp: gdsr data table (under `data`)
void add_train_command(CLI::App& app);  // train/cmd_train.cpp: gdsr train
void add_infer_command(CLI::App& app);  // infer/cmd_infer.cpp: gdsr infer
void add_eval_command(CLI::App& app);   // infer/cmd_eval.cpp: gdsr eval
void add_export_command(CLI::App& app); // infer/cmd_export.cpp: gdsr export
void add_weights_command(CLI::App& app); // train/cmd_weights.cpp: gdsr weights
void add_demo_command(CLI::App& app);   // train/cmd_demo.cpp: gdsr demo (the README's main job)
