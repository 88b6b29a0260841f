CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT);
CREATE TABLE demonstrations (
  id INTEGER PRIMARY KEY, kind TEXT,
  resolution REAL, nx INTEGER, ny INTEGER,
  center_x REAL, center_y REAL,
  ground_a REAL, ground_b REAL, ground_c REAL,
  start_x REAL, start_y REAL, start_heading REAL,
  expert_x REAL, expert_y REAL, expert_heading REAL,
  elevation BLOB, class BLOB);
INSERT INTO meta VALUES ('format', 'autoshovel-demonstrations-1');
INSERT INTO demonstrations VALUES (1, 'pile_front', 0.5, 2, 1, 10, 10, 0, 0, 0, 4, 5, 0, 12, 10, 0.1, X'0000803F00000040', X'0101');
INSERT INTO demonstrations VALUES (7, 'pile_front', -0.5, 2, 1, 10, 10, 0, 0, 0, 4, 5, 0, 12, 10, 0.1, X'0000803F00000040', X'0101');
