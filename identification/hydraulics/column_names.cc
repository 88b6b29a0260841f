#include "identification/hydraulics/column_names.h"

#include <algorithm>

namespace autoshovel::identification {

void ColumnNames::Add(int cell, const std::string& name, const std::string& row) {
  if (name.empty()) return;
  for (const Entry& entry : entries_) {
    if (entry.cell == cell && entry.name == name) return;
  }
  entries_.push_back({cell, name, row});
}

std::vector<int> ColumnNames::Find(const std::string& name) const {
  std::vector<int> cells;
  for (const Entry& entry : entries_) {
    if (entry.name == name) cells.push_back(entry.cell);
  }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  return cells;
}

std::string ColumnNames::RowsNaming(const std::string& name, const std::vector<int>& cells) const {
  std::vector<std::string> rows;
  for (const Entry& entry : entries_) {
    if (entry.name != name || std::find(cells.begin(), cells.end(), entry.cell) == cells.end()) {
      continue;
    }
    if (std::find(rows.begin(), rows.end(), entry.row) == rows.end()) rows.push_back(entry.row);
  }
  std::string text;
  for (const std::string& row : rows) text += (text.empty() ? "" : ", ") + row;
  return text;
}

std::pair<std::string, std::string> ColumnNames::UniqueName(int cell) const {
  std::pair<std::string, std::string> best;
  for (const Entry& entry : entries_) {
    if (entry.cell != cell || Find(entry.name).size() != 1) continue;
    if (best.first.empty() || entry.name.size() < best.first.size()) {
      best = {entry.name, entry.row};
    }
  }
  return best;
}

std::string ColumnNames::FirstName(int cell) const {
  for (const Entry& entry : entries_) {
    if (entry.cell == cell) return entry.name;
  }
  return "";
}

std::vector<std::string> ColumnNames::All() const {
  std::vector<std::string> names;
  for (const Entry& entry : entries_) {
    if (std::find(names.begin(), names.end(), entry.name) == names.end()) {
      names.push_back(entry.name);
    }
  }
  return names;
}

std::string ColumnRanges(const std::vector<int>& cells) {
  std::string text;
  for (std::size_t i = 0; i < cells.size();) {
    std::size_t j = i;
    while (j + 1 < cells.size() && cells[j + 1] == cells[j] + 1) ++j;
    if (!text.empty()) text += ", ";
    if (j >= i + 2) {
      text += std::to_string(cells[i] + 1) + ".." + std::to_string(cells[j] + 1);
      i = j + 1;
    } else {
      text += std::to_string(cells[i] + 1);
      ++i;
    }
  }
  return text;
}

}  // namespace autoshovel::identification
